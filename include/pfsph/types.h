/* Basic types shared by every pfsph module: the real type, error reporting, limits. */
#ifndef PFSPH_TYPES_H
#define PFSPH_TYPES_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#define PFSPH_VERSION "0.1.0"

#ifdef PFSPH_DOUBLE
typedef double pfsph_real;
#define PFSPH_REAL_NAME "double"
#define pfsph_sqrt sqrt
#else
typedef float pfsph_real;
#define PFSPH_REAL_NAME "float"
#define pfsph_sqrt sqrtf
#endif

#define PFSPH_MAX_PHASES 16
#define PFSPH_PATH_LEN 1024 /* file paths, including the terminating zero */

/* Status codes: the library never exits; programs map these to exit statuses. */
enum {
    PFSPH_OK = 0,
    PFSPH_EINPUT = -2,    /* bad scene / file content (program exit status 2) */
    PFSPH_EIO = -5,       /* file system error */
    PFSPH_ENOMEM = -12,   /* allocation failed or memory estimate too large */
    PFSPH_EUNSTABLE = -3, /* simulation blew up (program exit status 3) */
};

/* A human readable message: "file: JSON path: reason". Filled by the function that fails. */
typedef struct pfsph_error {
    int code;
    char msg[1024];
} pfsph_error;

/* printf-style helper; returns code so callers can `return pfsph_fail(err, ...)`. */
int pfsph_fail(pfsph_error *err, int code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#endif
