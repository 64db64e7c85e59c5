/*
 * fuzz_rgbe.c - libFuzzer harness for the RGBE reader and the cross cutter.
 *
 * Build and run: make -C reference/fuzz fuzz  (see the Makefile there).
 * Besides "no crash, no out-of-bounds access", every input checks the
 * promises envmap.h makes:
 *   - a failure returns a negative em_status, leaves the image empty and
 *     names the file in its message;
 *   - decoded values are finite and non-negative;
 *   - a decoded image, written and read back, is bit-identical (RGBE values
 *     re-encode exactly; those below the writer's 1e-32 cut become 0);
 *   - a cross cut into faces and put back matches on the six face cells.
 */
#include "envmap.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define NAME "fuzz.hdr"
#define ROUND_TRIP_MAX_PIXELS 4096 /* keep the file round trip cheap */

static void require(int condition, const char *what)
{
    if (!condition) {
        fprintf(stderr, "fuzz_rgbe: broken promise: %s\n", what);
        abort();
    }
}

static void check_failure(int status, const em_error *err, const em_image *img)
{
    require(status < 0, "error codes are negative");
    require(err->code == status, "err.code equals the returned status");
    require(strstr(err->message, NAME) != NULL, "the message names the file");
    require(img->rgb == NULL && img->width == 0 && img->height == 0, "a failed read leaves the image empty");
}

static float largest_channel(const float *px)
{
    float m = px[0] > px[1] ? px[0] : px[1];
    return m > px[2] ? m : px[2];
}

static void check_round_trip(const em_image *img)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/fuzz_rgbe_%ld.hdr", (long)getpid());
    em_error err;
    require(em_rgbe_write(path, img, &err) == EM_OK, "a decoded image can be written");
    em_image back;
    require(em_rgbe_read(path, &back, &err) == EM_OK, "our own output reads back");
    remove(path);
    require(back.width == img->width && back.height == img->height, "round trip keeps the size");
    size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n; ++i) {
        const float *a = img->rgb + 3 * i, *b = back.rgb + 3 * i;
        int tiny = largest_channel(a) < 1e-32f;
        for (int c = 0; c < 3; ++c)
            require(b[c] == (tiny ? 0.0f : a[c]), "RGBE values round-trip exactly");
    }
    em_image_free(&back);
}

static void check_cross(const em_image *img)
{
    em_cubemap cube;
    em_error err;
    int status = em_cubemap_from_cross(img, &cube, &err);
    if (status != EM_OK) {
        require(status == EM_ERR_LAYOUT, "only the layout can be wrong");
        require(cube.texels == NULL, "a failed cut leaves the cube map empty");
        return;
    }
    require(cube.face_width == img->width / 3 && cube.face_height == img->height / 4, "face size");
    em_image back;
    require(em_cubemap_to_cross(&cube, &back, &err) == EM_OK, "to_cross of a cut cross");
    require(back.width == img->width && back.height == img->height, "to_cross keeps the size");
    static const int cells[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 3}, {1, 1}};
    int fw = cube.face_width;
    for (int f = 0; f < 6; ++f)
        for (int y = cells[f][1] * fw; y < (cells[f][1] + 1) * fw; ++y) {
            size_t at = 3 * ((size_t)y * (size_t)img->width + (size_t)(cells[f][0] * fw));
            require(memcmp(img->rgb + at, back.rgb + at, 3 * (size_t)fw * sizeof(float)) == 0,
                    "to_cross(from_cross(x)) == x on the face cells");
        }
    em_image_free(&back);
    em_cubemap_free(&cube);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    em_image img;
    em_error err;
    memset(&err, 0, sizeof err);
    int status = em_rgbe_read_memory(data, size, NAME, &img, &err);
    if (status != EM_OK) {
        check_failure(status, &err, &img);
        return 0;
    }
    require(img.width > 0 && img.height > 0 && img.rgb != NULL, "a read image is not empty");
    size_t n = (size_t)img.width * (size_t)img.height;
    for (size_t i = 0; i < 3 * n; ++i)
        require(isfinite(img.rgb[i]) && img.rgb[i] >= 0.0f, "decoded values are finite and >= 0");
    if (n <= ROUND_TRIP_MAX_PIXELS)
        check_round_trip(&img);
    check_cross(&img);
    em_image_free(&img);
    return 0;
}
