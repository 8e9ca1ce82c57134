/*
 * fuzz_input.h - a fuzz input read as a stream of typed values (the C
 * counterpart of LLVM's FuzzedDataProvider): each take_* consumes bytes
 * from the front and returns 0s once the input is used up, so every input
 * maps to one deterministic call sequence.
 */
#ifndef CDSP_FUZZ_INPUT_H
#define CDSP_FUZZ_INPUT_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

typedef struct {
    const uint8_t *p;
    size_t n;
} fz_in;

static inline uint8_t fz_u8(fz_in *in)
{
    uint8_t v = 0;
    if (in->n) {
        v = in->p[0];
        in->p++;
        in->n--;
    }
    return v;
}

static inline uint32_t fz_u32(fz_in *in)
{
    uint32_t v = 0;
    int i;
    for (i = 0; i < 4; i++)
        v |= (uint32_t)fz_u8(in) << (8 * i);
    return v;
}

static inline int32_t fz_i32(fz_in *in)
{
    uint32_t u = fz_u32(in);
    int32_t v;
    memcpy(&v, &u, sizeof v);
    return v;
}

/* An integer in [lo, hi] (hi - lo < 2^32). */
static inline long fz_range(fz_in *in, long lo, long hi)
{
    uint32_t u = hi - lo < 256 ? fz_u8(in) : fz_u32(in);
    return lo + (long)(u % (uint32_t)(hi - lo + 1));
}

/* A double: one selector byte picks a value class so that special values
 * come up often: NaN, +-Inf, 0, -0, huge, tiny, an integer, a value in
 * [lo, hi], or 8 raw bytes. */
static inline double fz_real(fz_in *in, double lo, double hi)
{
    uint8_t sel = fz_u8(in);
    switch (sel % 12) {
    case 0: return NAN;
    case 1: return sel & 0x10 ? INFINITY : -INFINITY;
    case 2: return sel & 0x10 ? 0.0 : -0.0;
    case 3: return (sel & 0x10 ? 1 : -1) * 1e300;
    case 4: return (sel & 0x10 ? 1 : -1) * 1e-300;
    case 5: return (double)fz_i32(in);
    case 6: {
        uint64_t u = (uint64_t)fz_u32(in) | (uint64_t)fz_u32(in) << 32;
        double v;
        memcpy(&v, &u, sizeof v);
        return v;
    }
    default: return lo + (hi - lo) * (double)fz_u32(in) / 4294967295.0;
    }
}

#endif
