/* lookup.c - the environment in a direction: the face a direction exits
 * through, its (u, v) on that face, and the texture filters that read the
 * face (docs/assignment.md, "What students write" and "Conventions").
 *
 * Lattice conventions (p is the pixel position on a face):
 *   - nearest and bilinear follow the handout literally: p = (u W, v H) and
 *     texel (x, y) sits on the integer lattice point (x, y). Nearest takes
 *     the texel whose cell [x, x+1) x [y, y+1) holds p, bilinear blends the
 *     four lattice points around p. So bilinear reproduces texel x exactly
 *     at u = x/W, the left edge of the cell nearest gives it: its image sits
 *     half a texel towards -u, -v from nearest's, and is constant over the
 *     last half-open cell [W-1, W], where the clamp makes x1 = x0 = W-1.
 *   - seamless uses texel centres: texel (x, y) sits at p = (x + 1/2,
 *     y + 1/2), i.e. bilinear's formula applied to p - (1/2, 1/2). Centres
 *     are symmetric under u -> 1 - u, which is what lets lattice points on
 *     either side of a face edge meet texels of the neighbouring face however
 *     the two faces are turned. Inside a face, seamless(u, v) equals
 *     bilinear(u - 1/(2W), v - 1/(2H)). It is continuous across the 12 edges
 *     and 8 corners of a cube map with square faces.
 *
 * Colours are computed in double from the float texels. No input (NaN,
 * infinity, denormal, out-of-range face or filter) reads outside the faces.
 */
#include "internal.h"

#include <math.h>
#include <stddef.h>

/* ---- faces and (u, v) ---------------------------------------------------- */

enum { AXIS_X = 0, AXIS_Y = 1, AXIS_Z = 2 };

/* docs/assignment.md's (u, v) table as data, one row per face in buffer order:
 * u = (1 + u_sign * d[u_axis] / m) / 2, v = (1 + v_sign * d[v_axis] / m) / 2,
 * with m the absolute value of the major component. */
typedef struct face_axes {
    int u_axis; double u_sign;
    int v_axis; double v_sign;
} face_axes;

static const face_axes FACE_AXES[6] = {
    {AXIS_Z, +1.0, AXIS_Y, +1.0},   /* +X: u = (1 + z/m)/2, v = (1 + y/m)/2 */
    {AXIS_Z, -1.0, AXIS_Y, +1.0},   /* -X: u = (1 - z/m)/2, v = (1 + y/m)/2 */
    {AXIS_X, +1.0, AXIS_Z, +1.0},   /* +Y: u = (1 + x/m)/2, v = (1 + z/m)/2 */
    {AXIS_X, +1.0, AXIS_Z, -1.0},   /* -Y: u = (1 + x/m)/2, v = (1 - z/m)/2 */
    {AXIS_X, +1.0, AXIS_Y, -1.0},   /* +Z: u = (1 + x/m)/2, v = (1 - y/m)/2 */
    {AXIS_X, +1.0, AXIS_Y, +1.0},   /* -Z: u = (1 + x/m)/2, v = (1 + y/m)/2 */
};

/* The axis of the largest |component|; ties go to the first of x, y, z.
 * Written without && or ?: so that random directions cost no mispredicted
 * branches: x unless y or z is larger, then y unless z is larger. */
static int major_axis(const double a[3])
{
    const int x_loses = (a[AXIS_X] < a[AXIS_Y]) | (a[AXIS_X] < a[AXIS_Z]);
    const int z_beats_y = a[AXIS_Z] > a[AXIS_Y];
    return x_loses * (AXIS_Y + z_beats_y);
}

/* Face and (u, v) of d. Divides by m and never squares, so any finite
 * non-zero length works, denormals included. */
static int direction_face_uv(const double d[3], double *u, double *v)
{
    const double a[3] = {fabs(d[0]), fabs(d[1]), fabs(d[2])};
    /* zero, NaN or infinite: no face */
    if (!(isfinite(d[0]) && isfinite(d[1]) && isfinite(d[2]))
        || (a[0] == 0.0 && a[1] == 0.0 && a[2] == 0.0)) {
        *u = *v = 0.5;
        return EM_FACE_NONE;
    }
    /* the face the direction exits through: the major axis and its sign */
    const int axis = major_axis(a);
    const double m = a[axis];
    const int face = 2 * axis + (d[axis] < 0.0);
    /* where the ray meets that face, from docs/assignment.md's table */
    const face_axes *t = &FACE_AXES[face];
    *u = 0.5 * (1.0 + t->u_sign * (d[t->u_axis] / m));
    *v = 0.5 * (1.0 + t->v_sign * (d[t->v_axis] / m));
    return face;
}

int em_direction_to_face(double x, double y, double z, double *u, double *v)
{
    const double d[3] = {x, y, z};
    double uu, vv;
    const int face = direction_face_uv(d, &uu, &vv);
    if (u)
        *u = uu;
    if (v)
        *v = vv;
    return face;
}

void em_direction_to_face_batch(const double *dirs, size_t n, int *faces_out,
                                double *uv_out)
{
    if (!dirs)
        return;
    for (size_t i = 0; i < n; i++) {
        double u, v;
        const int face = direction_face_uv(dirs + 3 * i, &u, &v);
        if (faces_out)
            faces_out[i] = face;
        if (uv_out) {
            uv_out[2 * i] = u;
            uv_out[2 * i + 1] = v;
        }
    }
}

/* ---- the faces as the filters see them ------------------------------------ */

typedef struct cube_view {
    const float *face[6];   /* first texel of each face */
    int width, height;
} cube_view;

/* 1 when cube can be read; the six face addresses (em_cubemap_face,
 * docs/assignment.md "Buffer") are looked up once per call, not per lookup. */
static int cube_view_init(const em_cubemap *cube, cube_view *view)
{
    if (!cube || !cube->texels || cube->face_width <= 0 || cube->face_height <= 0)
        return 0;
    for (int k = 0; k < 6; k++)
        view->face[k] = em_cubemap_face(cube, k);
    view->width = cube->face_width;
    view->height = cube->face_height;
    return 1;
}

static const float *texel(const cube_view *c, int face, int x, int y)
{
    return c->face[face] + 3 * ((size_t)y * (size_t)c->width + (size_t)x);
}

static int clamp_int(int value, int lo, int hi)
{
    return value < lo ? lo : value > hi ? hi : value;
}

/* u or v as the filters take it: in [0, 1], NaN read as the face centre. */
static double face_coordinate(double t)
{
    if (isnan(t))
        return 0.5;
    return t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
}

static void set_black(double rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0;
}

static void set_texel(const float *t, double rgb[3])
{
    rgb[0] = t[0];
    rgb[1] = t[1];
    rgb[2] = t[2];
}

/* ---- nearest: the handout's starting code -------------------------------- */

static void read_nearest(const cube_view *c, int face, double u, double v,
                         double rgb[3])
{
    const int x0 = clamp_int((int)(u * c->width), 0, c->width - 1);
    const int y0 = clamp_int((int)(v * c->height), 0, c->height - 1);
    set_texel(texel(c, face, x0, y0), rgb);
}

/* ---- bilinear: the handout's equations (1)-(3), clamped per face ----------- */

static void read_bilinear(const cube_view *c, int face, double u, double v,
                          double rgb[3])
{
    /* pixel position p = (uW, vH); texel (x, y) is lattice point (x, y) */
    const double px = u * c->width, py = v * c->height;
    /* the lattice point below-left of p (p >= 0, so truncation is floor);
     * alpha, beta the fractional parts of p */
    const int left = (int)px, bottom = (int)py;
    const double alpha = px - left, beta = py - bottom;
    /* lattice points p00, p10, p01, p11, clamped to [0, W-1] x [0, H-1]:
     * reading x = -1 or x = W may crash */
    const int x0 = clamp_int(left, 0, c->width - 1), x1 = clamp_int(left + 1, 0, c->width - 1);
    const int y0 = clamp_int(bottom, 0, c->height - 1), y1 = clamp_int(bottom + 1, 0, c->height - 1);
    const float *c00 = texel(c, face, x0, y0), *c10 = texel(c, face, x1, y0);
    const float *c01 = texel(c, face, x0, y1), *c11 = texel(c, face, x1, y1);
    for (int k = 0; k < 3; k++) {
        /* (1) c0 = (1-alpha) c00 + alpha c10, (2) c1 = (1-alpha) c01 + alpha c11 */
        const double c0 = (1.0 - alpha) * c00[k] + alpha * c10[k];
        const double c1 = (1.0 - alpha) * c01[k] + alpha * c11[k];
        /* (3) c = (1-beta) c0 + beta c1 */
        rgb[k] = (1.0 - beta) * c0 + beta * c1;
    }
}

/* ---- seamless: bilinear over texel centres, across face edges ------------- */

/* The texel of the face next to `face` that the lattice point (x, y) - one
 * step outside `face` in exactly one of x, y - falls on: the point's texel
 * centre on the extended face plane, turned back into a direction and looked
 * up. (That direction lands well inside the neighbour's texel: the
 * projection moves it less than half a texel.) */
static const float *texel_across_edge(const cube_view *c, int face, int x, int y)
{
    const face_axes *t = &FACE_AXES[face];
    const double u = (x + 0.5) / c->width, v = (y + 0.5) / c->height;
    /* invert the (u, v) table on the plane |d[axis]| = 1 */
    double d[3];
    d[face / 2] = (face % 2) ? -1.0 : 1.0;
    d[t->u_axis] = t->u_sign * (2.0 * u - 1.0);
    d[t->v_axis] = t->v_sign * (2.0 * v - 1.0);
    double nu, nv;
    const int next = direction_face_uv(d, &nu, &nv);
    const int nx = clamp_int((int)(nu * c->width), 0, c->width - 1);
    const int ny = clamp_int((int)(nv * c->height), 0, c->height - 1);
    return texel(c, next, nx, ny);
}

/* Lattice point (x, y) of `face`, for x in [-1, W] and y in [-1, H]: a
 * texel of the face, of a neighbour across an edge, or at a corner (outside
 * in both x and y) the average of the three texels meeting there, as GPUs'
 * seamless cube-map filtering does. */
static void seamless_lattice(const cube_view *c, int face, int x, int y, double out[3])
{
    const int inside_x = x >= 0 && x < c->width, inside_y = y >= 0 && y < c->height;
    if (inside_x && inside_y) {
        set_texel(texel(c, face, x, y), out);
    } else if (inside_x || inside_y) {
        set_texel(texel_across_edge(c, face, x, y), out);
    } else {
        const int cx = clamp_int(x, 0, c->width - 1), cy = clamp_int(y, 0, c->height - 1);
        const float *own = texel(c, face, cx, cy);
        const float *across_x = texel_across_edge(c, face, x, cy);
        const float *across_y = texel_across_edge(c, face, cx, y);
        for (int k = 0; k < 3; k++)
            out[k] = ((double)own[k] + across_x[k] + across_y[k]) / 3.0;
    }
}

static void read_seamless(const cube_view *c, int face, double u, double v,
                          double rgb[3])
{
    /* pixel position on the texel-centre lattice: texel (x, y) at (x+1/2, y+1/2) */
    const double px = u * c->width - 0.5, py = v * c->height - 0.5;
    /* lattice points around p (x0 in [-1, W-1]); alpha, beta the fractional parts */
    const double fx = floor(px), fy = floor(py);
    const double alpha = px - fx, beta = py - fy;
    const int x0 = (int)fx, y0 = (int)fy;
    double c00[3], c10[3], c01[3], c11[3];
    if (x0 >= 0 && y0 >= 0 && x0 + 1 < c->width && y0 + 1 < c->height) {
        /* inside the face: the four texels, as bilinear */
        set_texel(texel(c, face, x0, y0), c00);
        set_texel(texel(c, face, x0 + 1, y0), c10);
        set_texel(texel(c, face, x0, y0 + 1), c01);
        set_texel(texel(c, face, x0 + 1, y0 + 1), c11);
    } else {
        /* touching an edge: lattice points outside come from the neighbours */
        seamless_lattice(c, face, x0, y0, c00);
        seamless_lattice(c, face, x0 + 1, y0, c10);
        seamless_lattice(c, face, x0, y0 + 1, c01);
        seamless_lattice(c, face, x0 + 1, y0 + 1, c11);
    }
    for (int k = 0; k < 3; k++) {
        /* equations (1)-(3) */
        const double c0 = (1.0 - alpha) * c00[k] + alpha * c10[k];
        const double c1 = (1.0 - alpha) * c01[k] + alpha * c11[k];
        rgb[k] = (1.0 - beta) * c0 + beta * c1;
    }
}

/* ---- the public lookups ---------------------------------------------------- */

/* A filter: reads face `face` (0..5) at (u, v), both in [0, 1]. */
typedef void (*texture_reader)(const cube_view *c, int face, double u, double v,
                               double rgb[3]);

/* The reader of a filter; NULL for an unknown filter (which reads black). */
static texture_reader reader_of(em_filter filter)
{
    switch (filter) {
    case EM_FILTER_NEAREST: return read_nearest;
    case EM_FILTER_BILINEAR: return read_bilinear;
    case EM_FILTER_SEAMLESS: return read_seamless;
    default: return NULL;
    }
}

/* The loops take the reader as an argument that is constant at each call
 * site, so the compiler makes one loop per filter with the reader inlined.
 * Directions go in blocks, faces and (u, v) first, then the texture reads:
 * a short loop of independent reads lets the processor overlap the cache
 * misses of many lookups. */
enum { FETCH_BLOCK = 64 };

static inline void fetch_loop(const cube_view *c, texture_reader read,
                              const double *dirs, size_t n, double *rgb_out,
                              int *faces_out)
{
    for (size_t start = 0; start < n; start += FETCH_BLOCK) {
        const size_t count = n - start < FETCH_BLOCK ? n - start : FETCH_BLOCK;
        int face[FETCH_BLOCK];
        double u[FETCH_BLOCK], v[FETCH_BLOCK];  /* in [0, 1]: |component / m| <= 1 */
        for (size_t i = 0; i < count; i++)
            face[i] = direction_face_uv(dirs + 3 * (start + i), &u[i], &v[i]);
        for (size_t i = 0; i < count; i++) {
            double *rgb = rgb_out + 3 * (start + i);
            if (face[i] == EM_FACE_NONE || !read)
                set_black(rgb);
            else
                read(c, face[i], u[i], v[i], rgb);
        }
        if (faces_out)
            for (size_t i = 0; i < count; i++)
                faces_out[start + i] = face[i];
    }
}

static inline void read_texture_loop(const cube_view *c, texture_reader read,
                                     const int *faces, const double *uv, size_t n,
                                     double *rgb_out)
{
    for (size_t i = 0; i < n; i++) {
        const int face = faces[i];
        if (face < 0 || face > 5 || !read)
            set_black(rgb_out + 3 * i);
        else
            read(c, face, face_coordinate(uv[2 * i]), face_coordinate(uv[2 * i + 1]),
                 rgb_out + 3 * i);
    }
}

void em_fetch_batch(const em_cubemap *cube, em_filter filter,
                    const double *dirs, size_t n, double *rgb_out, int *faces_out)
{
    cube_view view;
    if (!dirs || !rgb_out)
        return;
    if (!cube_view_init(cube, &view)) {
        fetch_loop(&view, NULL, dirs, n, rgb_out, faces_out);
        return;
    }
    switch (filter) {
    case EM_FILTER_NEAREST: fetch_loop(&view, read_nearest, dirs, n, rgb_out, faces_out); break;
    case EM_FILTER_BILINEAR: fetch_loop(&view, read_bilinear, dirs, n, rgb_out, faces_out); break;
    case EM_FILTER_SEAMLESS: fetch_loop(&view, read_seamless, dirs, n, rgb_out, faces_out); break;
    default: fetch_loop(&view, NULL, dirs, n, rgb_out, faces_out); break;
    }
}

void em_read_texture_batch(const em_cubemap *cube, em_filter filter,
                           const int *faces, const double *uv, size_t n,
                           double *rgb_out)
{
    cube_view view;
    if (!faces || !uv || !rgb_out)
        return;
    const texture_reader read = cube_view_init(cube, &view) ? reader_of(filter) : NULL;
    read_texture_loop(&view, read, faces, uv, n, rgb_out);
}

void em_fetch(const em_cubemap *cube, em_filter filter,
              double x, double y, double z, double rgb[3])
{
    const double d[3] = {x, y, z};
    if (rgb)
        em_fetch_batch(cube, filter, d, 1, rgb, NULL);
}

void em_read_texture(const em_cubemap *cube, em_filter filter, int face,
                     double u, double v, double rgb[3])
{
    const double uv[2] = {u, v};
    if (rgb)
        em_read_texture_batch(cube, filter, &face, uv, 1, rgb);
}

int em_cubemap_lookup_fn(void *context, const double *dirs, size_t n, double *rgb_out)
{
    const em_cubemap_lookup *lookup = context;
    if (!lookup || !lookup->cube || !dirs || !rgb_out)
        return EM_ERR_ARGUMENT;
    em_fetch_batch(lookup->cube, lookup->filter, dirs, n, rgb_out, NULL);
    return EM_OK;
}
