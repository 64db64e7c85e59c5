/* internal.h - helpers shared by the reference sources; not part of the API. */
#ifndef ENVMAP_INTERNAL_H
#define ENVMAP_INTERNAL_H

#include "envmap.h"

#if defined(__GNUC__)
#define EM_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define EM_PRINTF(a, b)
#endif

/* Fill *err (when not NULL) with code and "<name>: <formatted message>";
 * returns code, so a failing path reads `return em_fail(err, ...);`. */
int em_fail(em_error *err, int code, const char *name, const char *fmt, ...) EM_PRINTF(4, 5);

#endif
