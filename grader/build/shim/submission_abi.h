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

#define SUB_ABI_VERSION 2

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
/* The readTexture calls one fetchColor makes, as sub_record_fetch_batch logs
 * them: the face whose first texel `addr` is (0..5; -1: an address that is
 * no face's start), addr's distance from face 0's first texel in floats, u, v. */
#define SUB_RECORDED_CALLS 4
struct sub_texture_call { double face, offset, u, v; };
/* fetchColor for n directions with its readTexture calls recorded
 * (readTexture is virtual in the grader's EnvironmentMap.h): call k of
 * direction i is answered with tags[3*(k % SUB_RECORDED_CALLS)..+2] (never
 * the student's readTexture; a call with the same address, u and v as an
 * earlier logged one gets that one's tag) or, when tags is NULL, with the student's own
 * readTexture; the first SUB_RECORDED_CALLS are logged in
 * calls[SUB_RECORDED_CALLS*i + k]; summary[2*i] is how many calls there were
 * and summary[2*i+1] which logged call's answer fetchColor returned, bit for
 * bit (-1: none); rgb (n*3) is what it returned. */
int sub_record_fetch_batch(void *map, const double *dirs, size_t n, const double *tags, double *rgb,
                           double *summary, struct sub_texture_call *calls, char *message, size_t message_size);
/* loadFromCrossHDR(path): 1 on success, 0 on failure. */
int sub_load_cross(void *map, const char *path, char *message, size_t message_size);

#ifdef __cplusplus
}
#endif
#endif
