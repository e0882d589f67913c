/* Basic types shared by every pfsph module: the real type, error reporting, limits. */
#ifndef PFSPH_TYPES_H
#define PFSPH_TYPES_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

/* The public basics (status codes, pfsph_error, pfsph_real, PFSPH_VERSION and the precision)
 * are the embedding API's, defined once there. */
#include "pfsph.h"

#ifdef PFSPH_DOUBLE
#define PFSPH_REAL_NAME "double"
#define pfsph_sqrt sqrt
#else
#define PFSPH_REAL_NAME "float"
#define pfsph_sqrt sqrtf
#endif

#define PFSPH_MAX_PHASES 16
#define PFSPH_PATH_LEN 1024 /* file paths, including the terminating zero */

/* printf-style helper; returns code so callers can `return pfsph_fail(err, ...)`. */
int pfsph_fail(pfsph_error *err, int code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#endif
