/* scene.c - the scene-file reader (the handout's envmap_test.cfg syntax).
 *
 * Grammar (comments as in C: // to the end of the line, or from slash-star
 * to star-slash across lines; whitespace and newlines are free):
 *
 *   file   := block*
 *   block  := NAME '{' (NAME '=' value ';')* '}'
 *   value  := STRING                      "Cubemap/uffizi_cross.hdr"
 *           | NUMBER+                     1.5   or   0 1 -3
 *           | '(' NUMBER (',' NUMBER)* ')'  (0, 1, -3)
 *
 * STRING runs to the next '"' on the same line (no escapes); NUMBER is a
 * decimal with optional sign, fraction and exponent. Blocks (at most one
 * of each unless marked), keys and the defaults of keys left out; ranges and
 * types are in the key table below ("keys"), which this list must agree with
 * (tests/test_scene.py checks it):
 *
 *   camera            position = (0, 0, 0); look_at = (0, 0, -1) (the
 *                     handout's forward face); up = (0, 1, 0); fov = 45
 *                     (vertical, degrees); width = 512; height = 512;
 *   sampling          samples_per_pixel = 16; max_depth = 32; seed = 0;
 *   sphere            (any number) center, radius, material ("mirror" or
 *                     "glass") required; ior = 1.5 (glass only);
 *                     tint = (1, 1, 1);
 *   environment_light (required) filename required; hdr_gamma = 1;
 *
 * Every error is EM_ERR_SCENE with "<file>:<line>: <what>", e.g.
 * "envmap_test.cfg:12: unknown key 'radus' in sphere". A relative filename
 * is resolved against base_dir, the scene file's folder.
 */
#include "internal.h"
#include "scene.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A scene file is a few hundred bytes; refuse anything absurd before reading. */
#define SCENE_MAX_BYTES ((long)1 << 20)
#define VALUE_MAX_NUMBERS 4

/* ---- tokens ----------------------------------------------------------------- */

typedef enum token_kind { TOKEN_END, TOKEN_NAME, TOKEN_NUMBER, TOKEN_STRING, TOKEN_PUNCT } token_kind;

typedef struct token {
    token_kind kind;
    int line;
    const char *text;      /* NAME and STRING: the characters (no quotes) */
    size_t length;
    double number;
    char punct;            /* one of { } = ; ( ) , */
} token;

typedef struct parser {
    const char *at, *end;
    int line;
    const char *name;      /* the file name, for messages */
    em_error *err;
    token tok;             /* the current token */
} parser;

static int parse_error(parser *ps, int line, const char *fmt, ...) EM_PRINTF(3, 4);

static int parse_error(parser *ps, int line, const char *fmt, ...)
{
    char what[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return em_fail(ps->err, EM_ERR_SCENE, NULL, "%s:%d: %s", ps->name, line, what);
}

static int is_name_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
static int is_digit(char c) { return c >= '0' && c <= '9'; }
static int is_name_char(char c) { return is_name_start(c) || is_digit(c); }

/* Whitespace and both comment forms; counts lines. */
static int skip_blank(parser *ps)
{
    while (ps->at < ps->end) {
        char c = *ps->at;
        if (c == '\n') {
            ps->line++;
            ps->at++;
        } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
            ps->at++;
        } else if (c == '/' && ps->at + 1 < ps->end && ps->at[1] == '/') {
            while (ps->at < ps->end && *ps->at != '\n')
                ps->at++;
        } else if (c == '/' && ps->at + 1 < ps->end && ps->at[1] == '*') {
            int opened = ps->line;
            ps->at += 2;
            for (;;) {
                if (ps->at + 1 >= ps->end)
                    return parse_error(ps, opened, "unterminated /* comment");
                if (ps->at[0] == '*' && ps->at[1] == '/') {
                    ps->at += 2;
                    break;
                }
                if (*ps->at == '\n')
                    ps->line++;
                ps->at++;
            }
        } else {
            break;
        }
    }
    return EM_OK;
}

/* [+-]? digits [. digits] [e [+-] digits], at least one mantissa digit. */
static int lex_number(parser *ps, token *t)
{
    const char *p = ps->at, *start = ps->at;
    int digits = 0;
    if (*p == '+' || *p == '-')
        p++;
    while (p < ps->end && is_digit(*p)) { p++; digits++; }
    if (p < ps->end && *p == '.') {
        p++;
        while (p < ps->end && is_digit(*p)) { p++; digits++; }
    }
    if (digits && p < ps->end && (*p == 'e' || *p == 'E')) {
        const char *q = p + 1;
        if (q < ps->end && (*q == '+' || *q == '-'))
            q++;
        if (q < ps->end && is_digit(*q)) {
            while (q < ps->end && is_digit(*q))
                q++;
            p = q;
        }
    }
    if (!digits || (p < ps->end && (is_name_char(*p) || *p == '.')))
        return parse_error(ps, t->line, "malformed number '%.*s'",
                           (int)(p - start + (p < ps->end)), start);
    char buf[64];
    size_t n = (size_t)(p - start);
    if (n >= sizeof buf)
        return parse_error(ps, t->line, "number too long");
    memcpy(buf, start, n);
    buf[n] = '\0';
    char *stop;
    errno = 0;
    double value = strtod(buf, &stop);
    /* A stop short of the end means strtod disagrees with the grammar (a
     * locale with a decimal comma): report it rather than read a wrong value. */
    if (stop != buf + n)
        return parse_error(ps, t->line, "cannot read number '%s'", buf);
    if (!isfinite(value) || errno == ERANGE)
        return parse_error(ps, t->line, "number '%s' out of range", buf);
    t->kind = TOKEN_NUMBER;
    t->number = value;
    ps->at = p;
    return EM_OK;
}

/* Move to the next token (ps->tok). */
static int next_token(parser *ps)
{
    int status = skip_blank(ps);
    if (status)
        return status;
    token *t = &ps->tok;
    memset(t, 0, sizeof *t);
    t->line = ps->line;
    if (ps->at >= ps->end) {
        t->kind = TOKEN_END;
        return EM_OK;
    }
    char c = *ps->at;
    char c1 = ps->at + 1 < ps->end ? ps->at[1] : '\0';
    char c2 = ps->at + 2 < ps->end ? ps->at[2] : '\0';
    if (is_name_start(c)) {
        t->kind = TOKEN_NAME;
        t->text = ps->at;
        while (ps->at < ps->end && is_name_char(*ps->at))
            ps->at++;
        t->length = (size_t)(ps->at - t->text);
        return EM_OK;
    }
    if (is_digit(c) || (c == '.' && is_digit(c1)) ||
        ((c == '+' || c == '-') && (is_digit(c1) || (c1 == '.' && is_digit(c2)))))
        return lex_number(ps, t);
    if (c == '"') {
        const char *p = ps->at + 1;
        while (p < ps->end && *p != '"' && *p != '\n')
            p++;
        if (p >= ps->end || *p != '"')
            return parse_error(ps, t->line, "unterminated string");
        t->kind = TOKEN_STRING;
        t->text = ps->at + 1;
        t->length = (size_t)(p - t->text);
        ps->at = p + 1;
        return EM_OK;
    }
    if (strchr("{}=;(),", c) && c != '\0') {
        t->kind = TOKEN_PUNCT;
        t->punct = c;
        ps->at++;
        return EM_OK;
    }
    if ((unsigned char)c >= 0x21 && (unsigned char)c < 0x7f)
        return parse_error(ps, t->line, "unexpected character '%c'", c);
    return parse_error(ps, t->line, "unexpected byte 0x%02x", (unsigned)(unsigned char)c);
}

static int is_punct(const token *t, char c) { return t->kind == TOKEN_PUNCT && t->punct == c; }

static int name_is(const token *t, const char *s)
{
    return t->kind == TOKEN_NAME && strlen(s) == t->length && memcmp(t->text, s, t->length) == 0;
}

/* How a token reads in a message. */
static void describe(const token *t, char *buf, size_t size)
{
    switch (t->kind) {
    case TOKEN_END: snprintf(buf, size, "end of file"); break;
    case TOKEN_NAME: snprintf(buf, size, "'%.*s'", (int)(t->length > 64 ? 64 : t->length), t->text); break;
    case TOKEN_NUMBER: snprintf(buf, size, "number %g", t->number); break;
    case TOKEN_STRING: snprintf(buf, size, "string \"%.*s\"", (int)(t->length > 64 ? 64 : t->length), t->text); break;
    case TOKEN_PUNCT: snprintf(buf, size, "'%c'", t->punct); break;
    }
}

static int expected(parser *ps, const char *what)
{
    char got[96];
    describe(&ps->tok, got, sizeof got);
    return parse_error(ps, ps->tok.line, "expected %s, got %s", what, got);
}

static int expect_punct(parser *ps, char c)
{
    if (!is_punct(&ps->tok, c)) {
        char what[8] = {'\'', c, '\'', '\0'};
        return expected(ps, what);
    }
    return next_token(ps);
}

/* ---- values ------------------------------------------------------------------ */

typedef struct value {
    int line;
    int count;             /* numbers read; 0 for a string */
    double numbers[VALUE_MAX_NUMBERS];
    const char *text;      /* a string's characters */
    size_t length;
} value;

static int add_number(parser *ps, value *v)
{
    if (v->count == VALUE_MAX_NUMBERS)
        return parse_error(ps, ps->tok.line, "too many numbers in one value");
    v->numbers[v->count++] = ps->tok.number;
    return next_token(ps);
}

/* value ';' (the current token is the one after '='). */
static int parse_value(parser *ps, value *v)
{
    int status;
    memset(v, 0, sizeof *v);
    v->line = ps->tok.line;
    if (ps->tok.kind == TOKEN_STRING) {
        v->text = ps->tok.text;
        v->length = ps->tok.length;
        if ((status = next_token(ps)))
            return status;
    } else if (is_punct(&ps->tok, '(')) {
        if ((status = next_token(ps)))
            return status;
        for (;;) {
            if (ps->tok.kind != TOKEN_NUMBER)
                return expected(ps, "a number");
            if ((status = add_number(ps, v)))
                return status;
            if (is_punct(&ps->tok, ')'))
                break;
            if ((status = expect_punct(ps, ',')))
                return status;
        }
        if ((status = next_token(ps)))
            return status;
    } else if (ps->tok.kind == TOKEN_NUMBER) {
        while (ps->tok.kind == TOKEN_NUMBER)
            if ((status = add_number(ps, v)))
                return status;
    } else {
        return expected(ps, "a value (a number, a tuple or a \"string\")");
    }
    return expect_punct(ps, ';');
}

/* ---- keys -------------------------------------------------------------------- */

/* How a key's value is checked and where it goes: KEY_DOUBLE one number,
 * KEY_INT and KEY_UINT64 one whole number, KEY_VEC3 three numbers, KEY_STRING
 * a "string" (always stored by a setter). */
typedef enum key_type { KEY_DOUBLE, KEY_INT, KEY_UINT64, KEY_VEC3, KEY_STRING } key_type;
typedef double vec3[3];

typedef struct key_spec key_spec;
typedef struct block_spec block_spec;

/* For the few keys a plain store does not fit: check further, convert, and
 * store at `at` (the key's field). */
typedef int key_setter(parser *ps, const block_spec *block, const key_spec *key, void *at,
                       const value *v, const char *base_dir);

/* One key of a block, described once: the parser, the defaults and the
 * required-key check all read this. */
struct key_spec {
    const char *name;
    key_type type;
    size_t at;             /* offset of the field: in em_scene, or in em_sphere for sphere keys */
    double min, max;       /* KEY_DOUBLE and the integers: [min, max], or (min, max) when open */
    int open;
    int required;          /* else `def` is stored when the key is left out */
    double def[3];
    key_setter *set;       /* NULL: stored as its type says */
};

/* Where a block's keys go and how many of the block a file may have. */
typedef enum block_into { INTO_SCENE, INTO_SPHERE } block_into;
typedef enum block_times { AT_MOST_ONCE, ANY_NUMBER, EXACTLY_ONCE } block_times;

struct block_spec {
    const char *name;
    const key_spec *keys;
    int key_count;
    block_into into;       /* INTO_SPHERE: a new sphere per block, added at its '}' */
    block_times times;
};

static int set_material(parser *ps, const block_spec *block, const key_spec *key, void *at,
                        const value *v, const char *base_dir);
static int set_filename(parser *ps, const block_spec *block, const key_spec *key, void *at,
                        const value *v, const char *base_dir);
static int set_not_negative(parser *ps, const block_spec *block, const key_spec *key, void *at,
                            const value *v, const char *base_dir);

/* The table's columns. A field's offset is checked at compile time to have the
 * C type of the key's type (_Generic has no default). */
#define FIELD(in, field, ctype) _Generic(&((in *)0)->field, ctype *: offsetof(in, field))
#define DOUBLE_IN(in, field) KEY_DOUBLE, FIELD(in, field, double)
#define INT_IN(in, field) KEY_INT, FIELD(in, field, int)
#define UINT64_IN(in, field) KEY_UINT64, FIELD(in, field, uint64_t)
#define VEC3_IN(in, field) KEY_VEC3, FIELD(in, field, vec3)
#define STRING_IN(in, field, ctype) KEY_STRING, FIELD(in, field, ctype)
#define ANY 0, 0, 0
#define CLOSED(lo, hi) lo, hi, 0
#define OPEN(lo, hi) lo, hi, 1
#define REQUIRED 1, {0}
#define DEFAULT(...) 0, {__VA_ARGS__}

/* Each key, once. Columns: name; type and the field it is stored in; range;
 * default, or REQUIRED; setter (NULL: stored as its type says). The comment
 * at the top of this file lists the same keys and defaults
 * (tests/test_scene.py checks that they agree). */
static const key_spec camera_keys[] = {
    {"position", VEC3_IN(em_scene, camera.position), ANY, DEFAULT(0, 0, 0), NULL},
    /* The handout's forward face is -z (OpenGL): look down -z from the origin. */
    {"look_at", VEC3_IN(em_scene, camera.look_at), ANY, DEFAULT(0, 0, -1), NULL},
    {"up", VEC3_IN(em_scene, camera.up), ANY, DEFAULT(0, 1, 0), NULL},
    {"fov", DOUBLE_IN(em_scene, camera.fov_degrees), OPEN(0, 180), DEFAULT(45), NULL},
    {"width", INT_IN(em_scene, width), CLOSED(1, EM_SCENE_MAX_SIDE), DEFAULT(512), NULL},
    {"height", INT_IN(em_scene, height), CLOSED(1, EM_SCENE_MAX_SIDE), DEFAULT(512), NULL},
};
static const key_spec sampling_keys[] = {
    {"samples_per_pixel", INT_IN(em_scene, samples_per_pixel), CLOSED(1, EM_SCENE_MAX_SPP), DEFAULT(16), NULL},
    {"max_depth", INT_IN(em_scene, max_depth), CLOSED(0, EM_SCENE_MAX_DEPTH), DEFAULT(32), NULL},
    /* 2^53: every whole number up to it is exact in a double */
    {"seed", UINT64_IN(em_scene, seed), CLOSED(0, 9007199254740992.0), DEFAULT(0), NULL},
};
static const key_spec sphere_keys[] = {
    {"center", VEC3_IN(em_sphere, center), ANY, REQUIRED, NULL},
    {"radius", DOUBLE_IN(em_sphere, radius), OPEN(0, HUGE_VAL), REQUIRED, NULL},
    {"material", STRING_IN(em_sphere, material, em_material), ANY, REQUIRED, set_material},
    {"ior", DOUBLE_IN(em_sphere, ior), OPEN(0, HUGE_VAL), DEFAULT(1.5), NULL},
    {"tint", VEC3_IN(em_sphere, tint), ANY, DEFAULT(1, 1, 1), set_not_negative},
};
static const key_spec environment_keys[] = {
    {"filename", STRING_IN(em_scene, environment_path, char *), ANY, REQUIRED, set_filename},
    {"hdr_gamma", DOUBLE_IN(em_scene, hdr_gamma), OPEN(0, HUGE_VAL), DEFAULT(1), NULL},
};

enum { BLOCK_CAMERA, BLOCK_SAMPLING, BLOCK_SPHERE, BLOCK_ENVIRONMENT, BLOCK_COUNT };
#define KEY_COUNT(a) (int)(sizeof a / sizeof a[0])
/* The most keys a block has (parse_block keeps one line number per key). */
#define BLOCK_MAX_KEYS 6
_Static_assert(KEY_COUNT(camera_keys) <= BLOCK_MAX_KEYS, "camera keys");
_Static_assert(KEY_COUNT(sampling_keys) <= BLOCK_MAX_KEYS, "sampling keys");
_Static_assert(KEY_COUNT(sphere_keys) <= BLOCK_MAX_KEYS, "sphere keys");
_Static_assert(KEY_COUNT(environment_keys) <= BLOCK_MAX_KEYS, "environment keys");
static const block_spec blocks[BLOCK_COUNT] = {
    {"camera", camera_keys, KEY_COUNT(camera_keys), INTO_SCENE, AT_MOST_ONCE},
    {"sampling", sampling_keys, KEY_COUNT(sampling_keys), INTO_SCENE, AT_MOST_ONCE},
    {"sphere", sphere_keys, KEY_COUNT(sphere_keys), INTO_SPHERE, ANY_NUMBER},
    {"environment_light", environment_keys, KEY_COUNT(environment_keys), INTO_SCENE, EXACTLY_ONCE},
};

/* The key of block named text[0, length), or -1. */
static int key_index(const block_spec *block, const char *text, size_t length)
{
    for (int i = 0; i < block->key_count; i++)
        if (strlen(block->keys[i].name) == length && memcmp(block->keys[i].name, text, length) == 0)
            return i;
    return -1;
}

/* Check a value against its key's type and range. */
static int check_value(parser *ps, const block_spec *block, const key_spec *key, const value *v)
{
    const char *b = block->name, *k = key->name;
    if (key->type == KEY_STRING) {
        if (v->count)
            return parse_error(ps, v->line, "'%s' in %s expects a \"string\"", k, b);
        return EM_OK;
    }
    int want = key->type == KEY_VEC3 ? 3 : 1;
    if (v->count == 0)
        return parse_error(ps, v->line, "'%s' in %s expects %s, not a string", k, b,
                           want == 3 ? "3 numbers" : "a number");
    if (v->count != want)
        return parse_error(ps, v->line, "'%s' in %s expects %d number%s, got %d", k, b,
                           want, want == 1 ? "" : "s", v->count);
    if (key->type == KEY_VEC3)
        return EM_OK;
    double x = v->numbers[0];
    if (key->type != KEY_DOUBLE && x != floor(x))
        return parse_error(ps, v->line, "'%s' in %s must be a whole number, got %g", k, b, x);
    if (x < key->min || x > key->max || (key->open && (x == key->min || x == key->max))) {
        if (key->max == HUGE_VAL)
            return parse_error(ps, v->line, "'%s' in %s must be %s %g, got %g", k, b,
                               key->open ? ">" : ">=", key->min, x);
        return parse_error(ps, v->line, "'%s' in %s must be in %s%g, %g%s, got %g", k, b,
                           key->open ? "(" : "[", key->min, key->max, key->open ? ")" : "]", x);
    }
    return EM_OK;
}

/* ---- the scene ---------------------------------------------------------------- */

/* A number or vector key's value (a checked value, or its default). */
static void store_numbers(const key_spec *key, void *at, const double *x)
{
    switch (key->type) {
    case KEY_DOUBLE: *(double *)at = x[0]; break;
    case KEY_INT: *(int *)at = (int)x[0]; break;
    case KEY_UINT64: *(uint64_t *)at = (uint64_t)x[0]; break;
    case KEY_VEC3: memcpy(at, x, sizeof(vec3)); break;
    case KEY_STRING: break;    /* always required, always a setter */
    }
}

/* The defaults of a block's keys, into the scene or a new sphere. */
static void block_defaults(const block_spec *block, void *into)
{
    for (int i = 0; i < block->key_count; i++)
        if (!block->keys[i].required)
            store_numbers(&block->keys[i], (char *)into + block->keys[i].at, block->keys[i].def);
}

static void scene_defaults(em_scene *s)
{
    for (int i = 0; i < BLOCK_COUNT; i++)
        if (blocks[i].into == INTO_SCENE)
            block_defaults(&blocks[i], s);
}

static char *copy_text(const char *text, size_t length)
{
    char *out = malloc(length + 1);
    if (out) {
        memcpy(out, text, length);
        out[length] = '\0';
    }
    return out;
}

/* filename as is when absolute or when base_dir is empty, else base_dir/filename. */
static char *resolve_path(const char *base_dir, const char *file, size_t length)
{
    if (file[0] == '/' || !base_dir || !*base_dir)
        return copy_text(file, length);
    size_t base = strlen(base_dir);
    int slash = base_dir[base - 1] != '/';
    char *out = malloc(base + (size_t)slash + length + 1);
    if (out) {
        memcpy(out, base_dir, base);
        if (slash)
            out[base] = '/';
        memcpy(out + base + slash, file, length);
        out[base + slash + length] = '\0';
    }
    return out;
}

/* Store one checked key's value in the scene (sphere blocks: the block's sphere). */
static int store(parser *ps, em_scene *s, const block_spec *block, const key_spec *key, const value *v,
                 em_sphere *sphere, const char *base_dir)
{
    void *at = (block->into == INTO_SPHERE ? (char *)sphere : (char *)s) + key->at;
    if (key->set)
        return key->set(ps, block, key, at, v, base_dir);
    store_numbers(key, at, v->numbers);
    return EM_OK;
}

static int set_material(parser *ps, const block_spec *block, const key_spec *key, void *at,
                        const value *v, const char *base_dir)
{
    (void)block, (void)key, (void)base_dir;
    if (v->length == 6 && memcmp(v->text, "mirror", 6) == 0)
        *(em_material *)at = EM_MATERIAL_MIRROR;
    else if (v->length == 5 && memcmp(v->text, "glass", 5) == 0)
        *(em_material *)at = EM_MATERIAL_GLASS;
    else
        return parse_error(ps, v->line, "unknown material \"%.*s\" (expected \"mirror\" or \"glass\")",
                           (int)(v->length > 64 ? 64 : v->length), v->text);
    return EM_OK;
}

/* A file name, resolved against base_dir (the scene file's folder). */
static int set_filename(parser *ps, const block_spec *block, const key_spec *key, void *at,
                        const value *v, const char *base_dir)
{
    char **path = at;
    if (v->length == 0)
        return parse_error(ps, v->line, "'%s' in %s is empty", key->name, block->name);
    free(*path);
    *path = resolve_path(base_dir, v->text, v->length);
    if (!*path)
        return em_fail(ps->err, EM_ERR_NOMEM, ps->name, "out of memory");
    return EM_OK;
}

/* A vector whose numbers must all be >= 0 (a tint). */
static int set_not_negative(parser *ps, const block_spec *block, const key_spec *key, void *at,
                            const value *v, const char *base_dir)
{
    (void)base_dir;
    if (v->numbers[0] < 0 || v->numbers[1] < 0 || v->numbers[2] < 0)
        return parse_error(ps, v->line, "'%s' in %s must not be negative", key->name, block->name);
    store_numbers(key, at, v->numbers);
    return EM_OK;
}

/* Required keys and rules spanning keys, checked at the block's '}'. */
static int finish_block(parser *ps, int block, const int *key_lines, int open_line,
                        const em_scene *s, const em_sphere *sphere)
{
    const block_spec *spec = &blocks[block];
    for (int i = 0; i < spec->key_count; i++)
        if (spec->keys[i].required && !key_lines[i])
            return parse_error(ps, open_line, "%s has no '%s'", spec->name, spec->keys[i].name);
    if (block == BLOCK_SPHERE) {
        int ior = key_index(spec, "ior", strlen("ior"));
        if (ior >= 0 && key_lines[ior] && sphere->material != EM_MATERIAL_GLASS)
            return parse_error(ps, key_lines[ior], "'ior' applies to material \"glass\" only");
    }
    if (block == BLOCK_CAMERA) {
        const em_camera *c = &s->camera;
        double f[3], side[3];
        for (int i = 0; i < 3; i++)
            f[i] = c->look_at[i] - c->position[i];
        side[0] = f[1] * c->up[2] - f[2] * c->up[1];
        side[1] = f[2] * c->up[0] - f[0] * c->up[2];
        side[2] = f[0] * c->up[1] - f[1] * c->up[0];
        if (f[0] == 0 && f[1] == 0 && f[2] == 0)
            return parse_error(ps, open_line, "camera look_at equals its position");
        if (side[0] == 0 && side[1] == 0 && side[2] == 0)
            return parse_error(ps, open_line, "camera up is zero or parallel to the view direction");
    }
    return EM_OK;
}

static int add_sphere(parser *ps, em_scene *s, const em_sphere *sphere, int line)
{
    if (s->sphere_count == EM_SCENE_MAX_SPHERES)
        return parse_error(ps, line, "more than %d spheres", EM_SCENE_MAX_SPHERES);
    em_sphere *grown = realloc(s->spheres, sizeof *grown * (size_t)(s->sphere_count + 1));
    if (!grown)
        return em_fail(ps->err, EM_ERR_NOMEM, ps->name, "out of memory");
    s->spheres = grown;
    s->spheres[s->sphere_count++] = *sphere;
    return EM_OK;
}

/* block := NAME '{' (NAME '=' value ';')* '}' (the current token is NAME). */
static int parse_block(parser *ps, em_scene *s, int *block_lines, const char *base_dir)
{
    int status, open_line = ps->tok.line, block = -1;
    for (int i = 0; i < BLOCK_COUNT; i++)
        if (name_is(&ps->tok, blocks[i].name))
            block = i;
    if (block < 0) {
        char got[96];
        describe(&ps->tok, got, sizeof got);
        return parse_error(ps, open_line, "unknown block %s", got);
    }
    const block_spec *spec = &blocks[block];
    if (block_lines[block] && spec->times != ANY_NUMBER)
        return parse_error(ps, open_line, "second %s block (the first is at line %d)",
                           spec->name, block_lines[block]);
    block_lines[block] = open_line;
    if ((status = next_token(ps)) || (status = expect_punct(ps, '{')))
        return status;

    em_sphere sphere;
    memset(&sphere, 0, sizeof sphere);
    if (spec->into == INTO_SPHERE)
        block_defaults(spec, &sphere);
    int key_lines[BLOCK_MAX_KEYS] = {0};    /* line each key was set at, 0 = not set */
    while (!is_punct(&ps->tok, '}')) {
        if (ps->tok.kind == TOKEN_END)
            return parse_error(ps, ps->tok.line, "end of file inside %s block (opened at line %d)",
                               spec->name, open_line);
        if (ps->tok.kind != TOKEN_NAME)
            return expected(ps, "a key or '}'");
        int key = key_index(spec, ps->tok.text, ps->tok.length);
        if (key < 0)
            return parse_error(ps, ps->tok.line, "unknown key '%.*s' in %s",
                               (int)(ps->tok.length > 64 ? 64 : ps->tok.length), ps->tok.text, spec->name);
        int key_line = ps->tok.line;
        if (key_lines[key])
            return parse_error(ps, key_line, "'%s' set twice in %s (first at line %d)",
                               spec->keys[key].name, spec->name, key_lines[key]);
        key_lines[key] = key_line;
        value v;
        if ((status = next_token(ps)) || (status = expect_punct(ps, '=')) ||
            (status = parse_value(ps, &v)) ||
            (status = check_value(ps, spec, &spec->keys[key], &v)) ||
            (status = store(ps, s, spec, &spec->keys[key], &v, &sphere, base_dir)))
            return status;
    }
    if ((status = finish_block(ps, block, key_lines, open_line, s, &sphere)))
        return status;
    if (spec->into == INTO_SPHERE && (status = add_sphere(ps, s, &sphere, open_line)))
        return status;
    return next_token(ps);
}

int em_scene_parse(const char *text, size_t size, const char *name,
                   const char *base_dir, em_scene **out, em_error *err)
{
    if (!name)
        name = "<scene>";
    if (!out || (!text && size))
        return em_fail(err, EM_ERR_ARGUMENT, name, "no text or no output");
    *out = NULL;
    em_scene *s = calloc(1, sizeof *s);
    if (!s || !(s->name = copy_text(name, strlen(name)))) {
        free(s);
        return em_fail(err, EM_ERR_NOMEM, name, "out of memory");
    }
    scene_defaults(s);

    parser ps = {text, text + size, 1, name, err, {0}};
    int block_lines[BLOCK_COUNT] = {0};
    int status = next_token(&ps);
    while (!status && ps.tok.kind != TOKEN_END) {
        if (ps.tok.kind != TOKEN_NAME)
            status = expected(&ps, "a block name");
        else
            status = parse_block(&ps, s, block_lines, base_dir);
    }
    for (int i = 0; i < BLOCK_COUNT && !status; i++)
        if (blocks[i].times == EXACTLY_ONCE && !block_lines[i])
            status = parse_error(&ps, ps.line, "no %s block", blocks[i].name);
    if (status) {
        em_scene_free(s);
        return status;
    }
    *out = s;
    return EM_OK;
}

/* The folder part of path ("" when it has none), for relative filenames. */
static char *folder_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        return copy_text("", 0);
    return copy_text(path, slash == path ? 1 : (size_t)(slash - path));
}

int em_scene_load(const char *path, em_scene **out, em_error *err)
{
    if (!path || !out)
        return em_fail(err, EM_ERR_ARGUMENT, NULL, "no path or no output");
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f)
        return em_fail(err, EM_ERR_IO, path, "cannot open: %s", strerror(errno));
    char *text = malloc((size_t)SCENE_MAX_BYTES + 1);
    size_t size = text ? fread(text, 1, (size_t)SCENE_MAX_BYTES + 1, f) : 0;
    int read_failed = text && ferror(f);
    fclose(f);
    if (!text)
        return em_fail(err, EM_ERR_NOMEM, path, "out of memory");
    if (read_failed) {
        free(text);
        return em_fail(err, EM_ERR_IO, path, "cannot read");
    }
    if (size > (size_t)SCENE_MAX_BYTES) {
        free(text);
        return em_fail(err, EM_ERR_TOO_LARGE, path, "larger than %ld bytes: not a scene file", SCENE_MAX_BYTES);
    }
    char *folder = folder_of(path);
    int status = folder ? em_scene_parse(text, size, path, folder, out, err)
                        : em_fail(err, EM_ERR_NOMEM, path, "out of memory");
    free(folder);
    free(text);
    return status;
}

void em_scene_free(em_scene *scene)
{
    if (!scene)
        return;
    free(scene->name);
    free(scene->spheres);
    free(scene->environment_path);
    free(scene);
}

int em_scene_width(const em_scene *scene) { return scene ? scene->width : 0; }
int em_scene_height(const em_scene *scene) { return scene ? scene->height : 0; }

const char *em_scene_environment_path(const em_scene *scene)
{
    return scene && scene->environment_path ? scene->environment_path : "";
}

double em_scene_hdr_gamma(const em_scene *scene) { return scene ? scene->hdr_gamma : 1.0; }

/* Not checked here (these return nothing): em_trace refuses out-of-range values. */
void em_scene_set_resolution(em_scene *scene, int width, int height)
{
    if (scene) {
        scene->width = width;
        scene->height = height;
    }
}

void em_scene_set_samples(em_scene *scene, int samples_per_pixel)
{
    if (scene)
        scene->samples_per_pixel = samples_per_pixel;
}
