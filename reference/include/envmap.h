/*
 * envmap.h - the reference implementation of the cube-map environment-mapping
 * assignment (docs/assignment.md is the contract), as a C11 library with
 * no dependencies beyond libc and libm.
 *
 * Conventions (docs/assignment.md, "Conventions"):
 *   - faces are numbered +X, -X, +Y, -Y, +Z, -Z (0..5);
 *   - a cube map is one float RGB buffer face_width wide and 6*face_height
 *     tall; face k starts at k*W*H*3 floats; texel (x, y) of a face is at
 *     3*(y*W + x), y = 0 the bottom row (v = 0), x = 0 the left column (u = 0);
 *   - images (em_image) are stored top row first, as in the file.
 *
 * Errors are values: every call that can fail returns EM_OK (0) or a
 * negative em_status and fills an em_error with a message naming the file
 * and what is wrong. Nothing here aborts, prints or reads out of bounds.
 */
#ifndef ENVMAP_H
#define ENVMAP_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- errors ------------------------------------------------------------- */

typedef enum em_status {
    EM_OK = 0,
    EM_ERR_IO = -1,        /* cannot open / read / write the file */
    EM_ERR_FORMAT = -2,    /* not a Radiance file, bad header or resolution */
    EM_ERR_CORRUPT = -3,   /* scanline data truncated or inconsistent */
    EM_ERR_TOO_LARGE = -4, /* size refused before allocating */
    EM_ERR_LAYOUT = -5,    /* image is not a vertical cross */
    EM_ERR_NOMEM = -6,
    EM_ERR_ARGUMENT = -7,  /* caller error (NULL pointer, bad face, ...) */
    EM_ERR_SCENE = -8      /* scene file syntax or content error */
} em_status;

typedef struct em_error {
    int code;              /* an em_status */
    char message[512];     /* "<file>: <what is wrong>" */
} em_error;

/* ---- images and the RGBE format (rgbe.c) -------------------------------- */

/* A linear float RGB image, top row first, 3 floats per pixel. */
typedef struct em_image {
    int width, height;
    float *rgb;
} em_image;

/* Largest image the reader accepts (pixels); larger is EM_ERR_TOO_LARGE. */
#define EM_MAX_PIXELS ((size_t)1 << 28)

/* Read a Radiance RGBE (.hdr) file. Any of the eight resolution-line
 * orientations is turned into the standard one (-Y H +X W: top row first,
 * left to right). Decodes m * 2^(e - 136), 0 when e == 0 (as OpenImageIO and
 * stb do). On failure *out is left empty. */
int em_rgbe_read(const char *path, em_image *out, em_error *err);
/* The same from memory; name is used in messages only. */
int em_rgbe_read_memory(const unsigned char *data, size_t size,
                        const char *name, em_image *out, em_error *err);
/* Write new-style RLE RGBE (flat scanlines where RLE cannot encode the
 * width, i.e. width < 8 or >= 32768). */
int em_rgbe_write(const char *path, const em_image *image, em_error *err);
void em_image_free(em_image *image);

/* ---- cube maps (cross.c) ------------------------------------------------ */

typedef enum em_face {
    EM_FACE_NONE = -1,     /* zero, NaN or infinite direction */
    EM_FACE_POS_X = 0, EM_FACE_NEG_X = 1,
    EM_FACE_POS_Y = 2, EM_FACE_NEG_Y = 3,
    EM_FACE_POS_Z = 4, EM_FACE_NEG_Z = 5
} em_face;

typedef struct em_cubemap {
    int face_width, face_height;
    float *texels;         /* 6 * face_width * face_height * 3 floats */
} em_cubemap;

/* Cut the six faces out of a vertical cross (width/3 == height/4). */
int em_cubemap_from_cross(const em_image *cross, em_cubemap *out, em_error *err);
/* Read an .hdr vertical cross and cut it into faces. */
int em_cubemap_load_cross(const char *path, em_cubemap *out, em_error *err);
/* Allocate a cube map; texels zeroed. */
int em_cubemap_alloc(int face_width, int face_height, em_cubemap *out, em_error *err);
/* The inverse of em_cubemap_from_cross: unused cells are 0. */
int em_cubemap_to_cross(const em_cubemap *cube, em_image *out, em_error *err);
void em_cubemap_free(em_cubemap *cube);
/* First float of face `face` (NULL for a bad face). */
const float *em_cubemap_face(const em_cubemap *cube, int face);

/* ---- lookups (lookup.c) ------------------------------------------------- */

typedef enum em_filter {
    EM_FILTER_NEAREST = 0,  /* the handout's starting code */
    EM_FILTER_BILINEAR = 1, /* the handout's equations (1)-(3), per-face clamp: the grading reference */
    EM_FILTER_SEAMLESS = 2  /* bilinear taking texels across face edges, corners averaged */
} em_filter;

/* Face and (u, v) of a direction (need not be unit length). Ties between
 * components of equal magnitude go to the first face in the order
 * x, y, z (any touching face is correct, docs/assignment.md). Returns
 * EM_FACE_NONE, with u = v = 0.5, for zero, NaN or infinite components. */
int em_direction_to_face(double x, double y, double z, double *u, double *v);
/* Batch form: dirs n*3, faces_out n, uv_out n*2. */
void em_direction_to_face_batch(const double *dirs, size_t n, int *faces_out,
                                double *uv_out);

/* The face texture at (u, v), clamped to [0,1]; rgb gets 3 doubles. A NaN
 * u or v is treated as 0.5. A bad face gives black. */
void em_read_texture(const em_cubemap *cube, em_filter filter, int face,
                     double u, double v, double rgb[3]);
/* The environment in direction (x, y, z). EM_FACE_NONE directions give
 * black. */
void em_fetch(const em_cubemap *cube, em_filter filter,
              double x, double y, double z, double rgb[3]);

/* Batches: dirs and uv are packed (n*3 and n*2 doubles); rgb_out gets n*3
 * doubles; faces_out (may be NULL) gets the face chosen for each direction. */
void em_fetch_batch(const em_cubemap *cube, em_filter filter,
                    const double *dirs, size_t n, double *rgb_out, int *faces_out);
void em_read_texture_batch(const em_cubemap *cube, em_filter filter,
                           const int *faces, const double *uv, size_t n,
                           double *rgb_out);

/* ---- scenes and rendering (scene.c, render.c) --------------------------- */

typedef struct em_scene em_scene;

/* Parse a scene file in the handout's syntax (block { key = value; },
 * comments, strings, numbers, tuples). Relative paths inside it are
 * resolved against the scene file's folder. */
int em_scene_load(const char *path, em_scene **out, em_error *err);
int em_scene_parse(const char *text, size_t size, const char *name,
                   const char *base_dir, em_scene **out, em_error *err);
void em_scene_free(em_scene *scene);
int em_scene_width(const em_scene *scene);
int em_scene_height(const em_scene *scene);
/* The environment map file named by environment_light.filename (absolute
 * or resolved against base_dir), and its hdr_gamma. */
const char *em_scene_environment_path(const em_scene *scene);
double em_scene_hdr_gamma(const em_scene *scene);
/* Override the image size (e.g. for fixtures at a smaller resolution). */
void em_scene_set_resolution(em_scene *scene, int width, int height);
void em_scene_set_samples(em_scene *scene, int samples_per_pixel);

/* The environment lookup the renderer calls: n directions in, n RGB out
 * (batched, so a lookup in another process costs one round trip per batch). */
typedef int (*em_lookup_fn)(void *context, const double *dirs, size_t n,
                            double *rgb_out);

/* The renderer works in two steps so that the environment can be looked up
 * anywhere: em_trace follows every camera ray through mirrors and glass and
 * records where paths leave the scene (the direction, the pixel and the
 * path's throughput); em_resolve sums throughput * environment into pixels.
 * Deterministic: fixed seed, fixed sample pattern. */
typedef struct em_escapes {
    size_t count;
    double *dirs;          /* count*3 */
    double *weights;       /* count*3, RGB throughput, already divided by spp */
    uint32_t *pixels;      /* count, y*width + x, y = 0 the top row */
    int width, height;
    double hdr_gamma;      /* em_resolve uses environment colour^hdr_gamma */
} em_escapes;

int em_trace(const em_scene *scene, em_escapes *out, em_error *err);
/* rgb: escapes->count*3 environment colours for escapes->dirs; the image
 * is the sum over escapes of weight * rgb^hdr_gamma per pixel. */
int em_resolve(const em_escapes *escapes, const double *rgb, em_image *out, em_error *err);
void em_escapes_free(em_escapes *escapes);
/* Trace, look up with `lookup` in batches, resolve. */
int em_render(const em_scene *scene, em_lookup_fn lookup, void *context,
              em_image *out, em_error *err);

/* A ready-made em_lookup_fn over a cube map: context is an
 * em_cubemap_lookup. */
typedef struct em_cubemap_lookup {
    const em_cubemap *cube;
    em_filter filter;
} em_cubemap_lookup;
int em_cubemap_lookup_fn(void *context, const double *dirs, size_t n, double *rgb_out);

#ifdef __cplusplus
}
#endif
#endif /* ENVMAP_H */
