/* SPDX-License-Identifier: Apache-2.0 */
/* The simulators' seeded noise: splitmix64 uniforms and Box-Muller normals,
 * the same on every machine (br_simlog's force noise, the circle's drift-free
 * force and encoder noise). */
#ifndef BR_RNG_H
#define BR_RNG_H

#include <math.h>
#include <stdint.h>

typedef struct {
    uint64_t s;
    int have;
    double spare;
} br_rng_t;

/* uniform in (0, 1) */
static inline double br_rng_uniform(br_rng_t *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return ((double)(z >> 11) + 0.5) / 9007199254740992.0;
}

/* standard normal (Box-Muller, the second value kept for the next call) */
static inline double br_rng_gauss(br_rng_t *r)
{
    if (r->have) {
        r->have = 0;
        return r->spare;
    }
    const double u = br_rng_uniform(r), v = br_rng_uniform(r);
    const double m = sqrt(-2.0 * log(u));
    r->spare = m * sin(2.0 * 3.14159265358979323846 * v);
    r->have = 1;
    return m * cos(2.0 * 3.14159265358979323846 * v);
}

#endif
