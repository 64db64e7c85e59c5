/*
 * cross.c - cube maps and the vertical cross they are stored in.
 *
 * The cross and the face buffer are laid out as docs/assignment.md ("Vertical
 * cross", "Buffer") fixes them: cells in the image (column, row), row 0 at
 * the top,
 *
 *            [+Y]              (1,0)
 *      [-X]  [-Z]  [+X]    (0,1) (1,1) (2,1)
 *            [-Y]              (1,2)
 *            [+Z]              (1,3)   as it sits in the cross
 *
 * and faces copied without rotation. Images are stored top row first and
 * faces bottom row first (y = 0 is v = 0), so each face's rows are flipped.
 */
#include "internal.h"

#include <stdlib.h>
#include <string.h>

/* The cross cell of each face, in face order +X -X +Y -Y +Z -Z. */
static const struct { int column, row; } face_cell[6] = {
    {2, 1}, /* +X */
    {0, 1}, /* -X */
    {1, 0}, /* +Y */
    {1, 2}, /* -Y */
    {1, 3}, /* +Z */
    {1, 1}, /* -Z */
};

/* Row y of face `face` (y = 0 the bottom) starts at this pixel of the cross:
 * the face's bottom row is the cell's last image row. */
static size_t cross_pixel(int face, int y, int face_width, int face_height)
{
    size_t cross_width = 3 * (size_t)face_width;
    size_t image_row = (size_t)face_cell[face].row * (size_t)face_height + (size_t)(face_height - 1 - y);
    return image_row * cross_width + (size_t)face_cell[face].column * (size_t)face_width;
}

int em_cubemap_alloc(int face_width, int face_height, em_cubemap *out, em_error *err)
{
    if (!out)
        return em_fail(err, EM_ERR_ARGUMENT, "em_cubemap_alloc", "NULL argument");
    memset(out, 0, sizeof *out);
    if (face_width <= 0 || face_height <= 0)
        return em_fail(err, EM_ERR_ARGUMENT, "em_cubemap_alloc", "faces of %d x %d texels",
                       face_width, face_height);
    /* a cube map is no larger than the largest cross the reader accepts */
    if ((size_t)face_width * (size_t)face_height > EM_MAX_PIXELS / 12)
        return em_fail(err, EM_ERR_TOO_LARGE, "em_cubemap_alloc",
                       "faces of %d x %d texels are larger than the limit", face_width, face_height);
    float *texels = calloc(6 * (size_t)face_width * (size_t)face_height * 3, sizeof *texels);
    if (!texels)
        return em_fail(err, EM_ERR_NOMEM, "em_cubemap_alloc", "out of memory for faces of %d x %d texels",
                       face_width, face_height);
    out->face_width = face_width;
    out->face_height = face_height;
    out->texels = texels;
    return EM_OK;
}

void em_cubemap_free(em_cubemap *cube)
{
    if (!cube)
        return;
    free(cube->texels);
    cube->texels = NULL;
    cube->face_width = cube->face_height = 0;
}

const float *em_cubemap_face(const em_cubemap *cube, int face)
{
    if (!cube || !cube->texels || face < 0 || face > 5)
        return NULL;
    return cube->texels + (size_t)face * (size_t)cube->face_width * (size_t)cube->face_height * 3;
}

/* from_cross with the name used in messages (the file, when there is one). */
static int cubemap_from_cross(const em_image *cross, const char *name, em_cubemap *out, em_error *err)
{
    if (!cross || !out || !cross->rgb)
        return em_fail(err, EM_ERR_ARGUMENT, name, "em_cubemap_from_cross: NULL argument");
    memset(out, 0, sizeof *out);
    int w = cross->width, h = cross->height;
    if (w <= 0 || h <= 0 || w % 3 != 0 || h % 4 != 0 || w / 3 != h / 4)
        return em_fail(err, EM_ERR_LAYOUT, name,
                       "image of %d x %d pixels is not a vertical cross (width/3 must equal height/4, "
                       "both exactly: 3 x 4 square faces)", w, h);
    int size = w / 3;
    int status = em_cubemap_alloc(size, size, out, err);
    if (status != EM_OK)
        return status;
    size_t row_floats = (size_t)size * 3;
    for (int face = 0; face < 6; ++face) {
        float *dst = out->texels + (size_t)face * (size_t)size * row_floats;
        for (int y = 0; y < size; ++y)
            memcpy(dst + (size_t)y * row_floats, cross->rgb + 3 * cross_pixel(face, y, size, size),
                   row_floats * sizeof *dst);
    }
    return EM_OK;
}

int em_cubemap_from_cross(const em_image *cross, em_cubemap *out, em_error *err)
{
    return cubemap_from_cross(cross, "cross", out, err);
}

int em_cubemap_load_cross(const char *path, em_cubemap *out, em_error *err)
{
    if (!path || !out)
        return em_fail(err, EM_ERR_ARGUMENT, path, "em_cubemap_load_cross: NULL argument");
    memset(out, 0, sizeof *out);
    em_image cross;
    int status = em_rgbe_read(path, &cross, err);
    if (status != EM_OK)
        return status;
    status = cubemap_from_cross(&cross, path, out, err);
    em_image_free(&cross);
    return status;
}

int em_cubemap_to_cross(const em_cubemap *cube, em_image *out, em_error *err)
{
    if (!cube || !out || !cube->texels)
        return em_fail(err, EM_ERR_ARGUMENT, "em_cubemap_to_cross", "NULL argument");
    memset(out, 0, sizeof *out);
    int fw = cube->face_width, fh = cube->face_height;
    if (fw <= 0 || fh <= 0 || (size_t)fw * (size_t)fh > EM_MAX_PIXELS / 12)
        return em_fail(err, EM_ERR_ARGUMENT, "em_cubemap_to_cross", "faces of %d x %d texels", fw, fh);
    float *rgb = calloc(12 * (size_t)fw * (size_t)fh * 3, sizeof *rgb);
    if (!rgb)
        return em_fail(err, EM_ERR_NOMEM, "em_cubemap_to_cross", "out of memory for faces of %d x %d texels",
                       fw, fh);
    size_t row_floats = (size_t)fw * 3;
    for (int face = 0; face < 6; ++face) {
        const float *src = em_cubemap_face(cube, face);
        for (int y = 0; y < fh; ++y)
            memcpy(rgb + 3 * cross_pixel(face, y, fw, fh), src + (size_t)y * row_floats,
                   row_floats * sizeof *rgb);
    }
    out->width = 3 * fw;
    out->height = 4 * fh;
    out->rgb = rgb;
    return EM_OK;
}
