/*
 * reference_submission.c - the reference lookups behind the submission ABI.
 *
 * Built into build/reference_submission.so, this is a "submission" whose
 * answers are the reference's (em_fetch_batch / em_read_texture_batch,
 * bilinear). The speed check runs it in a worker of its own, interleaved with
 * the student's, as the baseline; harness tests use it as a correct
 * submission that needs no C++ build.
 */
#include "envmap.h"
#include "submission_abi.h"

#include <stdlib.h>
#include <string.h>

typedef struct reference_map {
    em_cubemap cube;       /* points at the worker's buffer; never freed here */
} reference_map;

int sub_abi_version(void) { return SUB_ABI_VERSION; }

void *sub_create(char *message, size_t message_size)
{
    (void)message; (void)message_size;
    return calloc(1, sizeof(reference_map));
}

void sub_destroy(void *map) { free(map); }

int sub_set_faces(void *map, const float *texels, int w, int h, char *message, size_t message_size)
{
    (void)message; (void)message_size;
    reference_map *m = map;
    m->cube.face_width = w;
    m->cube.face_height = h;
    m->cube.texels = (float *)texels;   /* read only: the lookups never write */
    return SUB_OK;
}

int sub_fetch_batch(void *map, const double *dirs, size_t n, double *rgb, char *message, size_t message_size)
{
    (void)message; (void)message_size;
    em_fetch_batch(&((reference_map *)map)->cube, EM_FILTER_BILINEAR, dirs, n, rgb, NULL);
    return SUB_OK;
}

int sub_read_texture_batch(void *map, const float *addr, const double *uv, size_t n, double *rgb,
                           char *message, size_t message_size)
{
    (void)message; (void)message_size;
    const reference_map *m = map;
    /* A one-face cube map starting at addr: read_texture only reads face 0. */
    em_cubemap face = { m->cube.face_width, m->cube.face_height, (float *)addr };
    for (size_t i = 0; i < n; ++i)
        em_read_texture(&face, EM_FILTER_BILINEAR, 0, uv[2 * i], uv[2 * i + 1], rgb + 3 * i);
    return SUB_OK;
}

/* The reference's fetchColor as a recording would see it: one readTexture
 * call at the table's face and (u, v), its answer (the tag, or the
 * reference's bilinear) returned. */
int sub_record_fetch_batch(void *map, const double *dirs, size_t n, const double *tags, double *rgb,
                           double *summary, struct sub_texture_call *calls, char *message, size_t message_size)
{
    (void)message; (void)message_size;
    const reference_map *m = map;
    const double face_floats = (double)m->cube.face_width * m->cube.face_height * 3;
    for (size_t i = 0; i < n; ++i) {
        double u, v;
        int face = em_direction_to_face(dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2], &u, &v);
        summary[2 * i] = face >= 0;
        summary[2 * i + 1] = face >= 0 ? 0 : -1;
        if (face >= 0) {
            calls[SUB_RECORDED_CALLS * i] = (struct sub_texture_call){ face, face * face_floats, u, v };
            if (tags)
                memcpy(rgb + 3 * i, tags, 3 * sizeof(double));
            else
                em_read_texture(&m->cube, EM_FILTER_BILINEAR, face, u, v, rgb + 3 * i);
        } else {
            rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = 0.0;
        }
    }
    return SUB_OK;
}

int sub_load_cross(void *map, const char *path, char *message, size_t message_size)
{
    (void)map; (void)path;
    if (message && message_size)
        message[0] = '\0';
    return 0;   /* the worker hands faces over with sub_set_faces */
}
