/* scene.h - the parsed scene (scene.c fills it, render.c reads it); not part
 * of the public API. Only what the scene files need: a pinhole camera,
 * mirror and glass spheres, and the environment map. */
#ifndef ENVMAP_SCENE_H
#define ENVMAP_SCENE_H

#include "envmap.h"

typedef enum em_material { EM_MATERIAL_MIRROR = 0, EM_MATERIAL_GLASS = 1 } em_material;

typedef struct em_sphere {
    double center[3];
    double radius;
    em_material material;
    double ior;            /* glass only: index of refraction inside */
    double tint[3];        /* mirror: reflectance; glass: transmittance per refraction */
} em_sphere;

typedef struct em_camera {
    double position[3], look_at[3], up[3];
    double fov_degrees;    /* vertical field of view */
} em_camera;

/* Limits the parser and em_trace enforce, so sizes never overflow. */
#define EM_SCENE_MAX_SIDE 16384
#define EM_SCENE_MAX_SPP 4096
#define EM_SCENE_MAX_DEPTH 64
#define EM_SCENE_MAX_SPHERES 1024

struct em_scene {
    char *name;            /* the file name, for messages */
    em_camera camera;
    int width, height;
    int samples_per_pixel;
    int max_depth;         /* surface interactions a path may have */
    uint64_t seed;
    em_sphere *spheres;
    int sphere_count;
    char *environment_path;
    double hdr_gamma;
};

#endif
