/*
 * submission_abi.h - the C entry points every built submission exposes.
 *
 * The grader compiles a student's EnvironmentMap.cpp together with our own
 * copies of the template (student_template/) and shim.cpp, which implements
 * these functions over the student's class. The worker (grader/worker/)
 * dlopen()s the result and calls only these. C++ exceptions never cross this
 * boundary: they are caught and returned as SUB_ERR_EXCEPTION with a message.
 */
#ifndef SUBMISSION_ABI_H
#define SUBMISSION_ABI_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SUB_ABI_VERSION 1

enum { SUB_OK = 0, SUB_ERR_EXCEPTION = -1, SUB_ERR_ARGUMENT = -2 };

int sub_abi_version(void);
/* A new EnvironmentMap with no texels (NULL when the constructor threw). */
void *sub_create(char *message, size_t message_size);
void sub_destroy(void *map);
/* Point the map at 6 faces of w x h RGB floats laid out as docs/assignment.md says;
 * the buffer is not copied (the worker places it between guard pages). */
int sub_set_faces(void *map, const float *texels, int w, int h,
                  char *message, size_t message_size);
/* fetchColor for n directions (n*3 doubles) -> rgb (n*3 doubles). */
int sub_fetch_batch(void *map, const double *dirs, size_t n, double *rgb,
                    char *message, size_t message_size);
/* readTexture(addr, u, v) for n (u, v) pairs (n*2 doubles) -> rgb (n*3). */
int sub_read_texture_batch(void *map, const float *addr, const double *uv,
                           size_t n, double *rgb, char *message, size_t message_size);
/* loadFromCrossHDR(path): 1 on success, 0 on failure. */
int sub_load_cross(void *map, const char *path, char *message, size_t message_size);

#ifdef __cplusplus
}
#endif
#endif
