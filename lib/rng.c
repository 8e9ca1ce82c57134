/*
 * rng.c - PCG32 (M. O'Neill, "PCG: A family of simple fast space-efficient
 * statistically good algorithms for random number generation", 2014).
 * The state is the caller's, so RANSAC and the renderer are reproducible
 * and reentrant.
 */
#include "internal.h"

void cdsp_rng_seed(cdsp_rng *rng, uint64_t seed, uint64_t stream)
{
    rng->state = 0u;
    rng->inc = (stream << 1u) | 1u;
    (void)cdsp_rng_u32(rng);
    rng->state += seed;
    (void)cdsp_rng_u32(rng);
}

uint32_t cdsp_rng_u32(cdsp_rng *rng)
{
    uint64_t old = rng->state;
    uint32_t xorshifted, rot;
    rng->state = old * 6364136223846793005ULL + rng->inc;
    xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    rot = (uint32_t)(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

/* Reject the partial bucket at the bottom so every residue is equally
 * likely: the 2^32 mod n lowest outputs, (2^32 - n) mod n in 32 bits. */
uint32_t cdsp__rng_threshold(uint32_t n)
{
    return (uint32_t)(0u - n) % n;
}

uint32_t cdsp__rng_below_t(cdsp_rng *rng, uint32_t n, uint32_t threshold)
{
    for (;;) {
        uint32_t r = cdsp_rng_u32(rng);
        if (r >= threshold)
            return r % n;
    }
}

uint32_t cdsp_rng_below(cdsp_rng *rng, uint32_t n)
{
    return cdsp__rng_below_t(rng, n, cdsp__rng_threshold(n));
}

cdsp_real cdsp_rng_uniform(cdsp_rng *rng)
{
#ifdef CDSP_SINGLE
    return (cdsp_real)(cdsp_rng_u32(rng) >> 8) * R(5.9604644775390625e-8); /* 2^-24 */
#else
    uint64_t hi = cdsp_rng_u32(rng) >> 5, lo = cdsp_rng_u32(rng) >> 6;
    return (cdsp_real)(hi * 67108864.0 + (double)lo) * (1.0 / 9007199254740992.0);
#endif
}

cdsp_real cdsp_rng_normal(cdsp_rng *rng)
{
    /* Marsaglia polar method; the second variate is discarded so the state
     * holds no hidden cache (simpler reproducibility across calls). */
    for (;;) {
        cdsp_real u = R(2) * cdsp_rng_uniform(rng) - R(1);
        cdsp_real v = R(2) * cdsp_rng_uniform(rng) - R(1);
        cdsp_real s = u * u + v * v;
        if (s > R(0) && s < R(1))
            return u * R_SQRT(R(-2) * R_LOG(s) / s);
    }
}
