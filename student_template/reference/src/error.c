/* error.c - errors as values with a message naming the file (stb style). */
#include "internal.h"

#include <stdarg.h>
#include <stdio.h>

int em_fail(em_error *err, int code, const char *name, const char *fmt, ...)
{
    if (err) {
        int used = 0;
        err->code = code;
        if (name && *name)
            used = snprintf(err->message, sizeof err->message, "%s: ", name);
        if (used < 0 || (size_t)used >= sizeof err->message)
            used = 0;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message + used, sizeof err->message - (size_t)used, fmt, ap);
        va_end(ap);
    }
    return code;
}
