/*
 * fuzz_input — what the fuzz targets share: a reader that turns the fuzzer's
 * bytes into numbers (running out of bytes reads zeros, so every input is a
 * complete, valid program), tables of the values that break naive code
 * (NaN, infinities, signed zeros, denormals, the ends of the range), and the
 * check that stops a run with a message when a guarantee does not hold.
 *
 * Header-only (static functions), C99. The checks abort() rather than
 * assert(), so that they also fire in builds with NDEBUG.
 */
#ifndef FUZZ_INPUT_H
#define FUZZ_INPUT_H

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Stops the run when cond is false, printing where and why. */
#define FUZZ_CHECK(cond, ...)                                                              \
    do {                                                                                   \
        if (!(cond)) {                                                                     \
            fprintf(stderr, "%s:%d: guarantee broken: %s\n  ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                                  \
            fputc('\n', stderr);                                                           \
            abort();                                                                       \
        }                                                                                  \
    } while (0)

typedef struct fuzz_reader {
    const uint8_t *data;
    size_t size, pos;
} fuzz_reader;

static inline void fuzz_reader_init(fuzz_reader *r, const uint8_t *data, size_t size) {
    r->data = data;
    r->size = size;
    r->pos = 0;
}

/* Next byte, 0 once the input is used up. */
static inline uint8_t fuzz_u8(fuzz_reader *r) {
    return r->pos < r->size ? r->data[r->pos++] : 0u;
}

static inline uint32_t fuzz_u32(fuzz_reader *r) {
    uint32_t v = 0;
    int i;
    for (i = 0; i < 4; ++i)
        v |= (uint32_t)fuzz_u8(r) << (8 * i);
    return v;
}

/* Raw bit patterns, any double or float at all (NaNs with payloads too). */
static inline double fuzz_raw_double(fuzz_reader *r) {
    uint64_t bits = 0;
    double d;
    int i;
    for (i = 0; i < 8; ++i)
        bits |= (uint64_t)fuzz_u8(r) << (8 * i);
    memcpy(&d, &bits, sizeof d);
    return d;
}

static inline float fuzz_raw_float(fuzz_reader *r) {
    uint32_t bits = fuzz_u32(r);
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* Doubles that break naive code: zeros of both signs, the smallest denormal,
 * the smallest normal, values whose sums absorb or overflow, the largest
 * finite, infinities and NaN, negatives, and a few ordinary numbers. */
#define FUZZ_SPECIAL_DOUBLES 32u
static inline double fuzz_special_double(unsigned i) {
    switch (i % FUZZ_SPECIAL_DOUBLES) {
    case 0:
        return 0.0;
    case 1:
        return -0.0;
    case 2:
        return 1.0;
    case 3:
        return 0.5;
    case 4:
        return 2.0;
    case 5:
        return 1e-3;
    case 6:
        return 1e3;
    case 7:
        return 0x1p-1074; /* the smallest denormal */
    case 8:
        return DBL_MIN;
    case 9:
        return 1e-300;
    case 10:
        return 1e-17; /* vanishes when added to 1 */
    case 11:
        return 1e300;
    case 12:
        return DBL_MAX;
    case 13:
        return (double)INFINITY;
    case 14:
        return -(double)INFINITY;
    case 15:
        return (double)NAN;
    case 16:
        return -1.0;
    case 17:
        return -DBL_MIN;
    case 18:
        return 1.0 + DBL_EPSILON;
    case 19:
        return 1.0 - DBL_EPSILON / 2.0;
    case 20:
        return 0.1;
    case 21:
        return 3.0;
    case 22:
        return 1e16;
    case 23:
        return 1e-9;
    case 24:
        return 7.0;
    case 25:
        return 0.25;
    case 26:
        return 100.0;
    case 27:
        return 1e-12;
    case 28:
        return DBL_MAX / 2.0; /* two of them overflow */
    case 29:
        return -1e300;
    case 30:
        return 4.0;
    default:
        return 1e-200;
    }
}

/* A double: mostly ordinary positive values spread over 2^-6 .. 2^8 (so
 * that most inputs build selectable scenes), else a special value or raw
 * bits. */
static inline double fuzz_double(fuzz_reader *r) {
    uint8_t b = fuzz_u8(r);
    if (b < FUZZ_SPECIAL_DOUBLES)
        return fuzz_special_double(b);
    if (b >= 248)
        return fuzz_raw_double(r);
    return ldexp(1.0 + (double)(b & 15u) / 16.0, (int)(b >> 4) - 7);
}

/* Floats for bounds: zeros, denormals, the ends of the range, infinities,
 * NaN, raw bits; otherwise coordinates in [-98, 111] in steps of 7/8. */
static inline float fuzz_float(fuzz_reader *r) {
    uint8_t b = fuzz_u8(r);
    switch (b) {
    case 0:
        return 0.0f;
    case 1:
        return -0.0f;
    case 2:
        return 0x1p-149f;
    case 3:
        return FLT_MIN;
    case 4:
        return FLT_MAX;
    case 5:
        return -FLT_MAX;
    case 6:
        return INFINITY;
    case 7:
        return -INFINITY;
    case 8:
        return NAN;
    case 9:
        return 1e30f;
    case 10:
        return -1e30f;
    case 11:
        return 1e-30f;
    case 12:
        return -1.0f;
    case 13:
        return 1e4f;
    case 14:
        return -1e4f;
    case 15:
        return fuzz_raw_float(r);
    default:
        return (float)((int)b - 128) * 0.875f;
    }
}

/* A callback value is bad when NaN, infinite or negative (-0.0 is not). */
static inline int fuzz_bad(double v) {
    return !(v >= 0.0) || isinf(v);
}

#endif /* FUZZ_INPUT_H */
