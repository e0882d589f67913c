/* Shared helpers for tests: paths, temporary directories, running the pfsph program. */
#ifndef PFSPH_TESTUTIL_H
#define PFSPH_TESTUTIL_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

/* Source directory (argv[1] / PFSPH_SOURCE_DIR) and pfsph program (argv[2] / PFSPH_BIN). */
void tu_init(int argc, char **argv);
const char *tu_source_dir(void);
const char *tu_pfsph_bin(void);
/* A fresh empty directory under /tmp, removed by tu_cleanup (registered with atexit). */
const char *tu_tmpdir(void);
/* Write text to a file; returns 0 on success. */
int tu_write_file(const char *path, const char *text);
/* Run a shell command, capturing stdout+stderr into out (truncated to cap). Returns the exit
 * status (or -1). */
int tu_run(const char *cmd, char *out, size_t cap);

#endif
