/*
 * null_submission.c - a submission whose lookups do nothing (every colour 0).
 *
 * The speed check times a pass of n lookups as the CPU time the kernel
 * charges to the worker process, which includes reading the n directions
 * and writing the n colours. Timing this library over the same directions
 * measures that protocol cost alone, so it can be taken off both the
 * student's time and the reference's. Ours, like the worker: never student code.
 */
#include <stdlib.h>
#include <string.h>

#include "../build/shim/submission_abi.h"

int sub_abi_version(void) { return SUB_ABI_VERSION; }
void *sub_create(char *message, size_t size) { (void)message; (void)size; return malloc(1); }
void sub_destroy(void *map) { free(map); }
int sub_set_faces(void *map, const float *texels, int w, int h, char *message, size_t size)
{ (void)map; (void)texels; (void)w; (void)h; (void)message; (void)size; return SUB_OK; }
int sub_fetch_batch(void *map, const double *dirs, size_t n, double *rgb, char *message, size_t size)
{ (void)map; (void)dirs; (void)message; (void)size; memset(rgb, 0, n * 3 * sizeof *rgb); return SUB_OK; }
int sub_read_texture_batch(void *map, const float *addr, const double *uv, size_t n, double *rgb,
                           char *message, size_t size)
{ (void)map; (void)addr; (void)uv; (void)message; (void)size; memset(rgb, 0, n * 3 * sizeof *rgb); return SUB_OK; }
int sub_record_fetch_batch(void *map, const double *dirs, size_t n, const double *tags, double *rgb,
                           double *counts, struct sub_texture_call *calls, char *message, size_t size)
{ (void)map; (void)dirs; (void)n; (void)tags; (void)rgb; (void)counts; (void)calls; (void)message; (void)size; return SUB_OK; }
int sub_load_cross(void *map, const char *path, char *message, size_t size)
{ (void)map; (void)path; (void)message; (void)size; return 0; }
