/* Error message formatting shared by all modules. */
#include <stdarg.h>
#include <stdio.h>

#include "pfsph/types.h"

int pfsph_fail(pfsph_error *err, int code, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        err->code = code;
    }
    return code;
}
