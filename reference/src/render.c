/* render.c - the minimal renderer: a pinhole camera, mirror and glass
 * spheres, and the environment as the background (smallpt-sized on purpose).
 *
 * Rendering is split in two (envmap.h): em_trace follows camera paths and
 * records where each leaves the scene; em_resolve sums throughput times the
 * environment colour into pixels. em_render does both with a lookup callback,
 * a batch of rows at a time, adding up each pixel in the same order as
 * em_resolve, so the two give bit-identical images.
 *
 * Sampling: samples_per_pixel jittered samples on an m x k grid over the pixel
 * (m the largest divisor of spp not above sqrt(spp), k = spp / m: 4 x 4 for
 * 16), jitter from splitmix64 keyed by (seed, pixel index), so a pixel's
 * samples do not depend on which other pixels are traced.
 *
 * Materials: a mirror reflects perfectly (throughput times tint). Glass
 * splits every hit into a reflected branch weighted by the exact
 * (unpolarised) dielectric Fresnel reflectance F and a refracted branch
 * (Snell) weighted by (1 - F) times tint; total internal reflection gives
 * F = 1. No Russian roulette: each sample is noise-free and deterministic. A
 * path that would need more than max_depth surface interactions contributes
 * black, and so does a branch whose throughput has fallen below
 * MIN_THROUGHPUT of its sample's; with a white environment and white tints,
 * 1 - pixel value is exactly the energy those two rules lose.
 */
#include "internal.h"
#include "scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
/* A branch whose throughput falls below this share of its sample is dropped
 * (black): such branches change no pixel visibly, and dropping them halves
 * the escapes (each one a lookup) of a glass sphere at max_depth 16. */
#define MIN_THROUGHPUT 1e-6
/* Escapes em_render hands to the lookup at a time. */
#define LOOKUP_BATCH ((size_t)65536)

/* ---- vectors ------------------------------------------------------------------- */

typedef struct vec3 { double x, y, z; } vec3;

static vec3 v3(const double a[3]) { vec3 v = {a[0], a[1], a[2]}; return v; }
static vec3 add(vec3 a, vec3 b) { vec3 v = {a.x + b.x, a.y + b.y, a.z + b.z}; return v; }
static vec3 sub(vec3 a, vec3 b) { vec3 v = {a.x - b.x, a.y - b.y, a.z - b.z}; return v; }
static vec3 scale(vec3 a, double s) { vec3 v = {a.x * s, a.y * s, a.z * s}; return v; }
static vec3 mul(vec3 a, vec3 b) { vec3 v = {a.x * b.x, a.y * b.y, a.z * b.z}; return v; }
static double dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static vec3 cross(vec3 a, vec3 b)
{
    vec3 v = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    return v;
}
static vec3 normalize(vec3 a) { return scale(a, 1.0 / sqrt(dot(a, a))); }

/* ---- the escape list ------------------------------------------------------------ */

static int escapes_push(em_escapes *e, size_t *capacity, vec3 dir, vec3 weight, uint32_t pixel)
{
    if (e->count == *capacity) {
        size_t grown = *capacity ? *capacity * 2 : 4096;
        if (grown > SIZE_MAX / (3 * sizeof(double)))
            return EM_ERR_NOMEM;
        double *dirs = realloc(e->dirs, grown * 3 * sizeof *dirs);
        if (dirs)
            e->dirs = dirs;
        double *weights = realloc(e->weights, grown * 3 * sizeof *weights);
        if (weights)
            e->weights = weights;
        uint32_t *pixels = realloc(e->pixels, grown * sizeof *pixels);
        if (pixels)
            e->pixels = pixels;
        if (!dirs || !weights || !pixels)
            return EM_ERR_NOMEM;
        *capacity = grown;
    }
    double *d = e->dirs + 3 * e->count, *w = e->weights + 3 * e->count;
    dir = normalize(dir);
    d[0] = dir.x; d[1] = dir.y; d[2] = dir.z;
    w[0] = weight.x; w[1] = weight.y; w[2] = weight.z;
    e->pixels[e->count++] = pixel;
    return EM_OK;
}

void em_escapes_free(em_escapes *escapes)
{
    if (!escapes)
        return;
    free(escapes->dirs);
    free(escapes->weights);
    free(escapes->pixels);
    memset(escapes, 0, sizeof *escapes);
}

/* ---- random numbers ---------------------------------------------------------------- */

/* splitmix64 (Steele, Lea, Flood 2014): tiny, and any key gives a good stream. */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double next_uniform(uint64_t *state)
{
    *state += 0x9e3779b97f4a7c15ull;
    return (double)(mix64(*state) >> 11) * 0x1.0p-53;   /* [0, 1) */
}

/* ---- scene geometry -------------------------------------------------------------------- */

typedef struct camera_frame {
    vec3 origin, forward, right, up;
    double tan_half_fov, aspect;
} camera_frame;

static camera_frame frame_of(const em_scene *s)
{
    camera_frame f;
    f.origin = v3(s->camera.position);
    f.forward = normalize(sub(v3(s->camera.look_at), f.origin));
    f.right = normalize(cross(f.forward, v3(s->camera.up)));
    f.up = cross(f.right, f.forward);
    f.tan_half_fov = tan(s->camera.fov_degrees * PI / 360.0);
    f.aspect = (double)s->width / s->height;
    return f;
}

/* The nearest t > 0 where the ray o + t d (|d| = 1) meets the sphere, or
 * HUGE_VAL. The discriminant is taken as r^2 - |oc - b d|^2 and the roots as
 * q and c/q, which keeps precision for hits near the origin. */
static double hit_sphere(const em_sphere *sp, vec3 o, vec3 d)
{
    vec3 oc = sub(o, v3(sp->center));
    double b = dot(oc, d);
    vec3 off_axis = sub(oc, scale(d, b));
    double r2 = sp->radius * sp->radius;
    double h = r2 - dot(off_axis, off_axis);
    if (h < 0)
        return HUGE_VAL;
    double q = b > 0 ? -b - sqrt(h) : -b + sqrt(h);
    if (q == 0)
        return HUGE_VAL;
    double t0 = (dot(oc, oc) - r2) / q, t1 = q;
    if (t0 > t1) { double t = t0; t0 = t1; t1 = t; }
    if (t0 > 0)
        return t0;
    return t1 > 0 ? t1 : HUGE_VAL;
}

/* Exact Fresnel reflectance of an unpolarised wave at a dielectric
 * boundary, cos_i and cos_t the cosines of incidence and transmission,
 * eta = n_i / n_t. */
static double fresnel_dielectric(double cos_i, double cos_t, double eta)
{
    double r_perp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    double r_par = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (r_perp * r_perp + r_par * r_par);
}

typedef struct tracer {
    const em_scene *scene;
    em_escapes *out;
    size_t capacity;
    double min_weight;     /* MIN_THROUGHPUT / spp */
} tracer;

/* Follow one ray: record it when it escapes, else scatter (recursively for
 * the two glass branches). */
static int trace_ray(tracer *tr, vec3 o, vec3 d, vec3 weight, int depth, uint32_t pixel)
{
    const em_scene *s = tr->scene;
    if (weight.x < tr->min_weight && weight.y < tr->min_weight && weight.z < tr->min_weight)
        return EM_OK;    /* negligible: black */
    const em_sphere *hit = NULL;
    double t = HUGE_VAL;
    for (int i = 0; i < s->sphere_count; i++) {
        double ti = hit_sphere(&s->spheres[i], o, d);
        if (ti < t) {
            t = ti;
            hit = &s->spheres[i];
        }
    }
    if (!hit)
        return escapes_push(tr->out, &tr->capacity, d, weight, pixel);
    if (depth == s->max_depth)
        return EM_OK;    /* too deep: black */

    vec3 p = add(o, scale(d, t));
    vec3 n = normalize(sub(p, v3(hit->center)));
    int entering = dot(d, n) < 0;
    vec3 facing = entering ? n : scale(n, -1.0);     /* the normal on the ray's side */
    double cos_i = -dot(d, facing);
    /* Leave the surface by a hair on the side the new ray travels. */
    double eps = 1e-9 * (hit->radius + fabs(p.x) + fabs(p.y) + fabs(p.z));
    vec3 reflected = normalize(add(d, scale(facing, 2.0 * cos_i)));
    vec3 tint = v3(hit->tint);

    if (hit->material == EM_MATERIAL_MIRROR)
        return trace_ray(tr, add(p, scale(facing, eps)), reflected, mul(weight, tint), depth + 1, pixel);

    double eta = entering ? 1.0 / hit->ior : hit->ior;   /* n_incident / n_transmitted */
    double sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    double reflectance = 1.0, cos_t = 0.0;
    if (sin2_t < 1.0) {
        cos_t = sqrt(1.0 - sin2_t);
        reflectance = fresnel_dielectric(cos_i, cos_t, eta);
    }
    int status = trace_ray(tr, add(p, scale(facing, eps)), reflected, scale(weight, reflectance),
                           depth + 1, pixel);
    if (status || reflectance >= 1.0)
        return status;
    /* Snell: t = eta d + (eta cos_i - cos_t) n, n facing the incoming ray. */
    vec3 refracted = normalize(add(scale(d, eta), scale(facing, eta * cos_i - cos_t)));
    vec3 through = mul(scale(weight, 1.0 - reflectance), tint);
    return trace_ray(tr, sub(p, scale(facing, eps)), refracted, through, depth + 1, pixel);
}

static int largest_divisor_up_to_sqrt(int n)
{
    int m = (int)sqrt((double)n);
    while (m > 1 && n % m)
        m--;
    return m;
}

/* All samples of one row; appends its escapes in pixel, sample, branch order. */
static int trace_row(tracer *tr, const camera_frame *f, int y)
{
    const em_scene *s = tr->scene;
    int spp = s->samples_per_pixel;
    int columns = largest_divisor_up_to_sqrt(spp), rows = spp / columns;
    vec3 weight = {1.0 / spp, 1.0 / spp, 1.0 / spp};
    for (int x = 0; x < s->width; x++) {
        uint32_t pixel = (uint32_t)y * (uint32_t)s->width + (uint32_t)x;
        uint64_t rng = mix64(s->seed ^ mix64(pixel));
        for (int i = 0; i < spp; i++) {
            double sx = (i % columns + next_uniform(&rng)) / columns;
            double sy = (i / columns + next_uniform(&rng)) / rows;
            /* Film position in [-1, 1], +y up; pixel row 0 is the top. */
            double fx = 2.0 * (x + sx) / s->width - 1.0;
            double fy = 1.0 - 2.0 * (y + sy) / s->height;
            vec3 d = add(f->forward, add(scale(f->right, fx * f->tan_half_fov * f->aspect),
                                         scale(f->up, fy * f->tan_half_fov)));
            int status = trace_ray(tr, f->origin, normalize(d), weight, 0, pixel);
            if (status)
                return status;
        }
    }
    return EM_OK;
}

/* The settings can be changed after parsing (em_scene_set_*), so check here. */
static int check_scene(const em_scene *s, em_error *err)
{
    if (!s)
        return em_fail(err, EM_ERR_ARGUMENT, NULL, "no scene");
    if (s->width < 1 || s->height < 1 || s->width > EM_SCENE_MAX_SIDE || s->height > EM_SCENE_MAX_SIDE)
        return em_fail(err, EM_ERR_ARGUMENT, s->name, "image size %d x %d outside 1..%d",
                       s->width, s->height, EM_SCENE_MAX_SIDE);
    if (s->samples_per_pixel < 1 || s->samples_per_pixel > EM_SCENE_MAX_SPP)
        return em_fail(err, EM_ERR_ARGUMENT, s->name, "samples_per_pixel %d outside 1..%d",
                       s->samples_per_pixel, EM_SCENE_MAX_SPP);
    return EM_OK;
}

/* ---- trace, resolve, render ----------------------------------------------------------- */

int em_trace(const em_scene *scene, em_escapes *out, em_error *err)
{
    if (!out)
        return em_fail(err, EM_ERR_ARGUMENT, NULL, "no output");
    memset(out, 0, sizeof *out);
    int status = check_scene(scene, err);
    if (status)
        return status;
    tracer tr = {scene, out, 0, MIN_THROUGHPUT / scene->samples_per_pixel};
    camera_frame f = frame_of(scene);
    for (int y = 0; y < scene->height && !status; y++)
        status = trace_row(&tr, &f, y);
    if (status) {
        em_escapes_free(out);
        return em_fail(err, status, scene->name, "out of memory while tracing");
    }
    out->width = scene->width;
    out->height = scene->height;
    out->hdr_gamma = scene->hdr_gamma;
    return EM_OK;
}

/* The environment colour as the image uses it: colour^hdr_gamma (values <= 0
 * give 0 unless hdr_gamma is 1, where the colour is used as is). */
static double environment_term(double colour, double hdr_gamma)
{
    if (hdr_gamma == 1.0)
        return colour;
    return colour > 0 ? pow(colour, hdr_gamma) : 0.0;
}

/* sums[3*pixel + c] += weight * colour^hdr_gamma for escapes [first, first + n). */
static void accumulate(const em_escapes *e, size_t first, size_t n, const double *rgb, double *sums)
{
    for (size_t i = 0; i < n; i++) {
        const double *w = e->weights + 3 * (first + i);
        double *sum = sums + 3 * (size_t)e->pixels[first + i];
        for (int c = 0; c < 3; c++)
            sum[c] += w[c] * environment_term(rgb[3 * i + c], e->hdr_gamma);
    }
}

static int image_from_sums(const double *sums, int width, int height, em_image *out, em_error *err)
{
    size_t n = (size_t)width * (size_t)height * 3;
    out->rgb = malloc(n * sizeof *out->rgb);
    if (!out->rgb)
        return em_fail(err, EM_ERR_NOMEM, NULL, "out of memory for a %d x %d image", width, height);
    for (size_t i = 0; i < n; i++)
        out->rgb[i] = (float)sums[i];
    out->width = width;
    out->height = height;
    return EM_OK;
}

int em_resolve(const em_escapes *escapes, const double *rgb, em_image *out, em_error *err)
{
    if (!out || !escapes)
        return em_fail(err, EM_ERR_ARGUMENT, NULL, "no escapes or no output");
    memset(out, 0, sizeof *out);
    const em_escapes *e = escapes;
    if (e->width < 1 || e->height < 1 || (size_t)e->width * (size_t)e->height > EM_MAX_PIXELS)
        return em_fail(err, EM_ERR_ARGUMENT, NULL, "bad image size %d x %d", e->width, e->height);
    if (e->count && (!rgb || !e->weights || !e->pixels))
        return em_fail(err, EM_ERR_ARGUMENT, NULL, "missing colours, weights or pixels");
    size_t pixels = (size_t)e->width * (size_t)e->height;
    for (size_t i = 0; i < e->count; i++)
        if (e->pixels[i] >= pixels)
            return em_fail(err, EM_ERR_ARGUMENT, NULL, "escape %zu: pixel %u outside the %d x %d image",
                           i, (unsigned)e->pixels[i], e->width, e->height);
    double *sums = calloc(pixels * 3, sizeof *sums);
    if (!sums)
        return em_fail(err, EM_ERR_NOMEM, NULL, "out of memory for a %d x %d image", e->width, e->height);
    accumulate(e, 0, e->count, rgb, sums);
    int status = image_from_sums(sums, e->width, e->height, out, err);
    free(sums);
    return status;
}

/* Look up and add in every escape traced so far, in batches, then empty the list. */
static int flush(em_escapes *e, em_lookup_fn lookup, void *context, double *rgb, double *sums,
                 const char *name, em_error *err)
{
    for (size_t first = 0; first < e->count; first += LOOKUP_BATCH) {
        size_t n = e->count - first < LOOKUP_BATCH ? e->count - first : LOOKUP_BATCH;
        int status = lookup(context, e->dirs + 3 * first, n, rgb);
        if (status)
            return em_fail(err, status < 0 ? status : EM_ERR_ARGUMENT, name,
                           "environment lookup failed (status %d)", status);
        accumulate(e, first, n, rgb, sums);
    }
    e->count = 0;
    return EM_OK;
}

int em_render(const em_scene *scene, em_lookup_fn lookup, void *context,
              em_image *out, em_error *err)
{
    if (!out || !lookup)
        return em_fail(err, EM_ERR_ARGUMENT, NULL, "no lookup or no output");
    memset(out, 0, sizeof *out);
    int status = check_scene(scene, err);
    if (status)
        return status;
    size_t pixels = (size_t)scene->width * (size_t)scene->height;
    em_escapes batch = {0};
    batch.hdr_gamma = scene->hdr_gamma;
    tracer tr = {scene, &batch, 0, MIN_THROUGHPUT / scene->samples_per_pixel};
    camera_frame f = frame_of(scene);
    double *sums = calloc(pixels * 3, sizeof *sums);
    double *rgb = malloc(LOOKUP_BATCH * 3 * sizeof *rgb);
    if (!sums || !rgb)
        status = em_fail(err, EM_ERR_NOMEM, scene->name, "out of memory");
    /* A few rows at a time keeps memory at one batch, not the whole image's escapes. */
    for (int y = 0; y < scene->height && !status; y++) {
        if ((status = trace_row(&tr, &f, y)))
            status = em_fail(err, status, scene->name, "out of memory while tracing");
        else if (batch.count >= LOOKUP_BATCH || y == scene->height - 1)
            status = flush(&batch, lookup, context, rgb, sums, scene->name, err);
    }
    if (!status)
        status = image_from_sums(sums, scene->width, scene->height, out, err);
    em_escapes_free(&batch);
    free(sums);
    free(rgb);
    return status;
}
