/*
 * rgbe.c - Radiance RGBE (.hdr) files: read (header, resolution line in any
 * of the eight orientations, flat / old-style RLE / new-style RLE scanlines)
 * and write (new-style RLE). The format is Greg Ward's ("Real Pixels",
 * Graphics Gems II; Radiance's picture file notes).
 *
 * Every length read from the file is checked against what is left of the
 * data and of the scanline before it is used; sizes are refused before any
 * allocation that depends on them.
 */
#include "internal.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The fuzz build lowers this so that libFuzzer's memory limit catches leaks
 * and runaway allocations, not legitimately large (tiny-file, old-RLE) images. */
#ifndef EM_RGBE_PIXEL_LIMIT
#define EM_RGBE_PIXEL_LIMIT EM_MAX_PIXELS
#endif

#define HEADER_MAX 65536       /* bytes up to and including the resolution line */
#define RLE_MIN_WIDTH 8        /* new-style RLE encodes scanlines of 8..32767 pixels */
#define RLE_MAX_WIDTH 32767
#define RLE_MIN_RUN 4          /* the writer's shortest run worth a run code */
#define FILE_MAX ((size_t)EM_RGBE_PIXEL_LIMIT * 5 + HEADER_MAX)

/* The largest value RGBE holds: mantissa 255, exponent byte 255. */
#define RGBE_MAX_VALUE 0x1.fep126f /* 255 * 2^119 */

/* ---- reading: bytes in memory ------------------------------------------- */

typedef struct reader {
    const unsigned char *data;
    size_t size, pos;
    const char *name;
    em_error *err;
} reader;

/* The next line (without '\n' and a trailing '\r') inside the header limit,
 * or an error when the header has no end or is too long. */
static int header_line(reader *r, const char *looking_for, const char **line, size_t *len)
{
    size_t limit = r->size < HEADER_MAX ? r->size : HEADER_MAX;
    const unsigned char *start = r->data + r->pos;
    const unsigned char *nl = r->pos < limit ? memchr(start, '\n', limit - r->pos) : NULL;
    if (!nl) {
        if (limit == HEADER_MAX)
            return em_fail(r->err, EM_ERR_FORMAT, r->name,
                           "header is longer than %d bytes (no blank line and resolution line)",
                           HEADER_MAX);
        return em_fail(r->err, EM_ERR_FORMAT, r->name, "header has no end (the file ends before %s)",
                       looking_for);
    }
    *line = (const char *)start;
    *len = (size_t)(nl - start);
    if (*len > 0 && (*line)[*len - 1] == '\r')
        --*len;
    r->pos += (size_t)(nl - start) + 1;
    return EM_OK;
}

static int line_is(const char *line, size_t len, const char *word)
{
    size_t n = strlen(word);
    if (len < n || memcmp(line, word, n) != 0)
        return 0;
    for (size_t i = n; i < len; ++i) /* trailing blanks are tolerated */
        if (line[i] != ' ' && line[i] != '\t')
            return 0;
    return 1;
}

static int starts_with(const char *line, size_t len, const char *prefix)
{
    size_t n = strlen(prefix);
    return len >= n && memcmp(line, prefix, n) == 0;
}

/* Header lines up to the blank line: magic, FORMAT=, and anything else
 * (EXPOSURE=, GAMMA=, comments, ...) accepted and not applied, as OpenImageIO
 * and stb do not apply them either. */
static int read_header(reader *r)
{
    const char *line;
    size_t len;
    if (r->size < 2 || memcmp(r->data, "#?", 2) != 0)
        return em_fail(r->err, EM_ERR_FORMAT, r->name,
                       "not a Radiance file (it does not start with #?RADIANCE or #?RGBE)");
    int status = header_line(r, "the blank line that ends the header", &line, &len);
    if (status != EM_OK)
        return status;
    if (!line_is(line, len, "#?RADIANCE") && !line_is(line, len, "#?RGBE"))
        return em_fail(r->err, EM_ERR_FORMAT, r->name,
                       "not a Radiance file (first line \"%.*s\", expected #?RADIANCE or #?RGBE)",
                       (int)(len < 40 ? len : 40), line);
    for (;;) {
        status = header_line(r, "the blank line that ends the header", &line, &len);
        if (status != EM_OK)
            return status;
        if (len == 0)
            return EM_OK;
        if (starts_with(line, len, "FORMAT=")) {
            const char *value = line + 7;
            size_t n = len - 7;
            while (n > 0 && (value[n - 1] == ' ' || value[n - 1] == '\t'))
                --n;
            if (n != 15 || memcmp(value, "32-bit_rle_rgbe", 15) != 0)
                return em_fail(r->err, EM_ERR_FORMAT, r->name,
                               "FORMAT=%.*s is not supported (only 32-bit_rle_rgbe)",
                               (int)(n < 40 ? n : 40), value);
        }
    }
}

/* How scanlines map to the standard image (top row first, left to right):
 * the pixel at (scanline s, position p) goes to first + s*step_scan + p*step_pixel. */
typedef struct layout {
    int width, height;          /* of the image */
    int scanlines, scan_length; /* as stored in the file */
    ptrdiff_t first, step_scan, step_pixel;
} layout;

/* One "[+-][XY] <count>" pair; returns 0 when it is not one. */
static int parse_axis(const char **p, const char *end, char *sign, char *axis, long long *count)
{
    const char *s = *p;
    if (end - s < 2 || (s[0] != '+' && s[0] != '-') || (s[1] != 'X' && s[1] != 'Y'))
        return 0;
    *sign = s[0];
    *axis = s[1];
    s += 2;
    if (s == end || *s != ' ')
        return 0;
    while (s < end && *s == ' ')
        ++s;
    if (s == end || *s < '0' || *s > '9')
        return 0;
    long long n = 0;
    while (s < end && *s >= '0' && *s <= '9') {
        if (n < 1000000000000LL) /* saturate: anything this big is refused later */
            n = n * 10 + (*s - '0');
        ++s;
    }
    while (s < end && *s == ' ')
        ++s;
    *count = n;
    *p = s;
    return 1;
}

/* The resolution line, e.g. "-Y 1024 +X 768": the first pair is the axis
 * that advances from scanline to scanline, the second the one along a
 * scanline; +X runs left to right, -Y top to bottom (Radiance's Y is up). */
static int read_resolution(reader *r, layout *out)
{
    const char *line;
    size_t len;
    int status = header_line(r, "the resolution line", &line, &len);
    if (status != EM_OK)
        return status;
    const char *p = line, *end = line + len;
    char sign[2], axis[2];
    long long count[2];
    if (!parse_axis(&p, end, &sign[0], &axis[0], &count[0]) ||
        !parse_axis(&p, end, &sign[1], &axis[1], &count[1]) || p != end || axis[0] == axis[1])
        return em_fail(r->err, EM_ERR_FORMAT, r->name,
                       "bad resolution line \"%.*s\" (expected e.g. \"-Y 512 +X 768\")",
                       (int)(len < 60 ? len : 60), line);
    if (count[0] == 0 || count[1] == 0)
        return em_fail(r->err, EM_ERR_FORMAT, r->name, "image has zero size (\"%.*s\")",
                       (int)(len < 60 ? len : 60), line);
    if (count[0] > (long long)EM_RGBE_PIXEL_LIMIT || count[1] > (long long)EM_RGBE_PIXEL_LIMIT ||
        (unsigned long long)count[0] * (unsigned long long)count[1] > (unsigned long long)EM_RGBE_PIXEL_LIMIT)
        return em_fail(r->err, EM_ERR_TOO_LARGE, r->name,
                       "image of %lld x %lld pixels is larger than the limit of %llu pixels",
                       axis[0] == 'X' ? count[0] : count[1], axis[0] == 'X' ? count[1] : count[0],
                       (unsigned long long)EM_RGBE_PIXEL_LIMIT);

    out->scanlines = (int)count[0];
    out->scan_length = (int)count[1];
    out->width = (int)(axis[0] == 'X' ? count[0] : count[1]);
    out->height = (int)(axis[0] == 'Y' ? count[0] : count[1]);
    /* the step and starting column / row of each axis in the standard image */
    ptrdiff_t first = 0, step[2];
    for (int i = 0; i < 2; ++i) {
        if (axis[i] == 'X') {
            step[i] = sign[i] == '+' ? 1 : -1;
            if (sign[i] == '-')
                first += out->width - 1;
        } else {
            step[i] = sign[i] == '-' ? out->width : -(ptrdiff_t)out->width;
            if (sign[i] == '+')
                first += (ptrdiff_t)(out->height - 1) * out->width;
        }
    }
    out->first = first;
    out->step_scan = step[0];
    out->step_pixel = step[1];
    return EM_OK;
}

/* ---- reading: scanlines --------------------------------------------------- */

static int truncated(reader *r, int scanline, const char *what, long done, int length)
{
    return em_fail(r->err, EM_ERR_CORRUPT, r->name,
                   "scanline %d: data ends at %s %ld of the %d-pixel line", scanline, what, done, length);
}

/* New-style RLE: the four channels one after the other, each as runs
 * (code > 128: code-128 copies of the next byte) and literals (code bytes). */
static int read_rle_scanline(reader *r, unsigned char *px, int length, int scanline)
{
    for (int c = 0; c < 4; ++c) {
        int x = 0;
        while (x < length) {
            if (r->pos >= r->size)
                return truncated(r, scanline, "byte", x, length);
            int code = r->data[r->pos++];
            int is_run = code > 128;
            int count = is_run ? code - 128 : code;
            if (count == 0)
                return em_fail(r->err, EM_ERR_CORRUPT, r->name,
                               "scanline %d, channel %d: literal of 0 bytes", scanline, c);
            if (count > length - x)
                return em_fail(r->err, EM_ERR_CORRUPT, r->name,
                               "scanline %d, channel %d: %s of %d bytes passes the end of the %d-pixel line",
                               scanline, c, is_run ? "run" : "literal", count, length);
            size_t need = is_run ? 1 : (size_t)count;
            if (r->size - r->pos < need)
                return truncated(r, scanline, "byte", x, length);
            const unsigned char *in = r->data + r->pos;
            unsigned char *dst = px + 4 * (size_t)x + (size_t)c;
            if (is_run)
                for (int i = 0; i < count; ++i)
                    dst[4 * i] = in[0];
            else
                for (int i = 0; i < count; ++i)
                    dst[4 * i] = in[i];
            x += count;
            r->pos += need;
        }
    }
    return EM_OK;
}

/* Flat pixels with Radiance's old-style RLE: a (1, 1, 1, n) pixel repeats
 * the previous pixel n times, and each consecutive marker counts 256 times
 * more than the one before (n << 8, n << 16, ...). */
static int read_flat_scanline(reader *r, unsigned char *px, int length, int scanline)
{
    int x = 0;
    int shift = 0;
    while (x < length) {
        if (r->size - r->pos < 4)
            return truncated(r, scanline, "pixel", x, length);
        const unsigned char *in = r->data + r->pos;
        r->pos += 4;
        if (in[0] == 1 && in[1] == 1 && in[2] == 1) {
            if (x == 0)
                return em_fail(r->err, EM_ERR_CORRUPT, r->name,
                               "scanline %d: repeat marker with no pixel before it", scanline);
            uint64_t repeat = in[3] == 0 ? 0 : shift >= 32 ? UINT64_MAX : (uint64_t)in[3] << shift;
            if (repeat > (uint64_t)(length - x))
                return em_fail(r->err, EM_ERR_CORRUPT, r->name,
                               "scanline %d: repeat of %llu pixels passes the end of the %d-pixel line",
                               scanline, (unsigned long long)repeat, length);
            for (uint64_t i = 0; i < repeat; ++i, ++x)
                memcpy(px + 4 * (size_t)x, px + 4 * (size_t)(x - 1), 4);
            if (shift < 32)
                shift += 8;
        } else {
            memcpy(px + 4 * (size_t)x, in, 4);
            ++x;
            shift = 0;
        }
    }
    return EM_OK;
}

static int read_scanline(reader *r, unsigned char *px, int length, int scanline)
{
    const unsigned char *in = r->data + r->pos;
    int marker = r->size - r->pos >= 4 && in[0] == 2 && in[1] == 2 && in[2] < 128;
    if (marker && length >= RLE_MIN_WIDTH && length <= RLE_MAX_WIDTH) {
        int encoded = in[2] << 8 | in[3];
        if (encoded != length)
            return em_fail(r->err, EM_ERR_CORRUPT, r->name,
                           "scanline %d: RLE marker gives %d pixels, the line has %d",
                           scanline, encoded, length);
        r->pos += 4;
        return read_rle_scanline(r, px, length, scanline);
    }
    /* Outside 8..32767 a (2, 2, hi, lo) pixel is a pixel (Radiance, stb); one
     * that spells this very length is an RLE line the format cannot hold. */
    if (marker && (in[2] << 8 | in[3]) == length)
        return em_fail(r->err, EM_ERR_CORRUPT, r->name,
                       "scanline %d: new-style RLE cannot encode a %d-pixel line (it needs %d to %d)",
                       scanline, length, RLE_MIN_WIDTH, RLE_MAX_WIDTH);
    return read_flat_scanline(r, px, length, scanline);
}

/* 2^(e - 136) for each exponent byte e, 0 for e == 0. m * scale[e] is exact
 * in float for every mantissa and exponent, so decoding is bit-identical to
 * OpenImageIO and stb. */
static void rgbe_scales(float scale[256])
{
    scale[0] = 0.0f;
    for (int e = 1; e < 256; ++e)
        scale[e] = (float)ldexp(1.0, e - 136);
}

/* Grow the file-order pixel store to hold `need` pixels. It grows with the
 * data actually decoded, so a short file claiming a huge size fails on its
 * missing data before anything huge is allocated. */
static int reserve_pixels(reader *r, unsigned char **store, size_t *capacity, size_t need, size_t total)
{
    if (need <= *capacity)
        return EM_OK;
    size_t grown = *capacity < total / 2 ? *capacity * 2 : total;
    if (grown < need)
        grown = need;
    unsigned char *bigger = realloc(*store, grown * 4);
    if (!bigger)
        return em_fail(r->err, EM_ERR_NOMEM, r->name, "out of memory for %zu pixels", grown);
    *store = bigger;
    *capacity = grown;
    return EM_OK;
}

int em_rgbe_read_memory(const unsigned char *data, size_t size, const char *name,
                        em_image *out, em_error *err)
{
    if (!name || !*name)
        name = "<memory>";
    if (!out || (!data && size > 0))
        return em_fail(err, EM_ERR_ARGUMENT, name, "em_rgbe_read_memory: NULL argument");
    memset(out, 0, sizeof *out);
    reader r = {data, size, 0, name, err};
    layout lay = {0};
    int status = read_header(&r);
    if (status == EM_OK)
        status = read_resolution(&r, &lay);
    if (status != EM_OK)
        return status;

    size_t total = (size_t)lay.width * (size_t)lay.height;
    size_t length = (size_t)lay.scan_length;
    unsigned char *store = NULL;
    size_t capacity = 0;
    for (int s = 0; s < lay.scanlines; ++s) {
        status = reserve_pixels(&r, &store, &capacity, (size_t)(s + 1) * length, total);
        if (status == EM_OK)
            status = read_scanline(&r, store + 4 * (size_t)s * length, lay.scan_length, s);
        if (status != EM_OK) {
            free(store);
            return status;
        }
    }

    float *rgb = malloc(total * 3 * sizeof *rgb);
    if (!rgb) {
        free(store);
        return em_fail(err, EM_ERR_NOMEM, name, "out of memory for %d x %d pixels", lay.width, lay.height);
    }
    float scale[256];
    rgbe_scales(scale);
    for (size_t s = 0; s < (size_t)lay.scanlines; ++s) {
        ptrdiff_t row_start = lay.first + (ptrdiff_t)s * lay.step_scan;
        const unsigned char *in = store + 4 * s * length;
        for (size_t p = 0; p < length; ++p, in += 4) {
            float *px = rgb + 3 * (size_t)(row_start + (ptrdiff_t)p * lay.step_pixel);
            px[0] = (float)in[0] * scale[in[3]];
            px[1] = (float)in[1] * scale[in[3]];
            px[2] = (float)in[2] * scale[in[3]];
        }
    }
    free(store);
    out->width = lay.width;
    out->height = lay.height;
    out->rgb = rgb;
    return EM_OK;
}

/* The whole file in memory (freed by the caller). */
static int read_file(const char *path, unsigned char **data, size_t *size, em_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return em_fail(err, EM_ERR_IO, path, "cannot open: %s", strerror(errno));
    unsigned char *buf = NULL;
    size_t used = 0, capacity = 0;
    int status = EM_OK;
    for (;;) {
        if (used == capacity) {
            if (capacity >= FILE_MAX) {
                status = em_fail(err, EM_ERR_TOO_LARGE, path,
                                 "file is larger than %zu bytes, too large for an image of at most %llu pixels",
                                 (size_t)FILE_MAX, (unsigned long long)EM_RGBE_PIXEL_LIMIT);
                break;
            }
            size_t grown = capacity ? capacity * 2 : 1 << 20;
            if (grown > FILE_MAX)
                grown = FILE_MAX;
            unsigned char *bigger = realloc(buf, grown);
            if (!bigger) {
                status = em_fail(err, EM_ERR_NOMEM, path, "out of memory reading %zu bytes", grown);
                break;
            }
            buf = bigger;
            capacity = grown;
        }
        size_t got = fread(buf + used, 1, capacity - used, f);
        used += got;
        if (got == 0) {
            if (ferror(f))
                status = em_fail(err, EM_ERR_IO, path, "read error: %s", strerror(errno));
            break;
        }
    }
    fclose(f);
    if (status != EM_OK) {
        free(buf);
        return status;
    }
    *data = buf;
    *size = used;
    return EM_OK;
}

int em_rgbe_read(const char *path, em_image *out, em_error *err)
{
    if (!path || !out)
        return em_fail(err, EM_ERR_ARGUMENT, path, "em_rgbe_read: NULL argument");
    memset(out, 0, sizeof *out);
    unsigned char *data = NULL;
    size_t size = 0;
    int status = read_file(path, &data, &size, err);
    if (status == EM_OK)
        status = em_rgbe_read_memory(data ? data : (const unsigned char *)"", size, path, out, err);
    free(data);
    return status;
}

void em_image_free(em_image *image)
{
    if (!image)
        return;
    free(image->rgb);
    image->rgb = NULL;
    image->width = image->height = 0;
}

/* ---- writing ---------------------------------------------------------------- */

/* Greg Ward's conversion (as in stb_image_write): the largest channel's
 * frexp exponent is shared, mantissas are truncated to 8 bits. Values RGBE
 * cannot hold are made safe first: NaN and negatives become 0, anything above
 * the largest RGBE value (including +inf) becomes that value. */
static void float_to_rgbe(const float in[3], unsigned char out[4])
{
    float c[3];
    for (int i = 0; i < 3; ++i) {
        float v = in[i];
        c[i] = !(v > 0.0f) ? 0.0f : v > RGBE_MAX_VALUE ? RGBE_MAX_VALUE : v;
    }
    float largest = c[0] > c[1] ? c[0] : c[1];
    if (c[2] > largest)
        largest = c[2];
    if (largest < 1e-32f) {
        memset(out, 0, 4);
        return;
    }
    int e;
    /* scale is exactly 2^(8-e), so every c * scale is exact and below 256 */
    float scale = (float)frexp(largest, &e) * 256.0f / largest;
    for (int i = 0; i < 3; ++i)
        out[i] = (unsigned char)(c[i] * scale);
    out[3] = (unsigned char)(e + 128);
}

/* Length of the run of equal bytes at x, at most `cap`. */
static int run_length(const unsigned char *bytes, int length, int x, int cap)
{
    int n = 1;
    while (x + n < length && n < cap && bytes[x + n] == bytes[x])
        ++n;
    return n;
}

/* One channel of a scanline as new-style RLE into out; returns bytes written
 * (at most length + length/128 + 1). */
static size_t encode_channel(const unsigned char *bytes, int length, unsigned char *out)
{
    size_t n = 0;
    int x = 0;
    while (x < length) {
        int run = run_length(bytes, length, x, 127);
        if (run >= RLE_MIN_RUN) {
            out[n++] = (unsigned char)(128 + run);
            out[n++] = bytes[x];
            x += run;
            continue;
        }
        /* a literal up to the next run worth encoding, at most 128 bytes */
        int start = x;
        while (x < length && x - start < 128 && run_length(bytes, length, x, RLE_MIN_RUN) < RLE_MIN_RUN)
            ++x;
        out[n++] = (unsigned char)(x - start);
        memcpy(out + n, bytes + start, (size_t)(x - start));
        n += (size_t)(x - start);
    }
    return n;
}

static int write_pixels(FILE *f, const em_image *image)
{
    int w = image->width;
    int rle = w >= RLE_MIN_WIDTH && w <= RLE_MAX_WIDTH;
    size_t line_bytes = (size_t)w * 4;
    unsigned char *pixels = malloc(line_bytes);
    unsigned char *planes = malloc(line_bytes);
    unsigned char *encoded = malloc(4 + line_bytes + 4 * ((size_t)w / 128 + 1));
    int ok = pixels && planes && encoded;
    for (int y = 0; ok && y < image->height; ++y) {
        const float *row = image->rgb + (size_t)y * (size_t)w * 3;
        for (int x = 0; x < w; ++x)
            float_to_rgbe(row + 3 * (size_t)x, pixels + 4 * (size_t)x);
        if (!rle) {
            ok = fwrite(pixels, 1, line_bytes, f) == line_bytes;
            continue;
        }
        size_t n = 0;
        encoded[n++] = 2;
        encoded[n++] = 2;
        encoded[n++] = (unsigned char)(w >> 8);
        encoded[n++] = (unsigned char)(w & 0xff);
        for (int c = 0; c < 4; ++c) {
            for (int x = 0; x < w; ++x)
                planes[x] = pixels[4 * (size_t)x + (size_t)c];
            n += encode_channel(planes, w, encoded + n);
        }
        ok = fwrite(encoded, 1, n, f) == n;
    }
    free(pixels);
    free(planes);
    free(encoded);
    return ok;
}

int em_rgbe_write(const char *path, const em_image *image, em_error *err)
{
    if (!path || !image || !image->rgb)
        return em_fail(err, EM_ERR_ARGUMENT, path, "em_rgbe_write: NULL argument");
    if (image->width <= 0 || image->height <= 0)
        return em_fail(err, EM_ERR_ARGUMENT, path, "cannot write an image of %d x %d pixels",
                       image->width, image->height);
    if ((size_t)image->width * (size_t)image->height > EM_MAX_PIXELS)
        return em_fail(err, EM_ERR_TOO_LARGE, path,
                       "image of %d x %d pixels is larger than the limit of %zu pixels",
                       image->width, image->height, (size_t)EM_MAX_PIXELS);
    FILE *f = fopen(path, "wb");
    if (!f)
        return em_fail(err, EM_ERR_IO, path, "cannot create: %s", strerror(errno));
    errno = 0;
    int ok = fprintf(f, "#?RADIANCE\n# written by the envmap reference library\n"
                        "FORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n",
                     image->height, image->width) > 0;
    if (ok && !write_pixels(f, image))
        ok = 0;
    int saved = errno;
    if (fclose(f) != 0 && ok) {
        ok = 0;
        saved = errno;
    }
    if (!ok) {
        remove(path);
        return em_fail(err, EM_ERR_IO, path, "cannot write: %s", saved ? strerror(saved) : "out of memory");
    }
    return EM_OK;
}
