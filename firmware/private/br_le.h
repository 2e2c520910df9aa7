/* SPDX-License-Identifier: Apache-2.0 */
/* Little-endian fields of the link's payloads (docs/link.md, "Messages"),
 * written and read byte by byte so that the packing is the same on any host
 * (private to the firmware). */
#ifndef BR_LE_H
#define BR_LE_H

#include <stdint.h>
#include <string.h>

/* the low n bytes of v at p, least significant first (n <= 4) */
static inline void br_le_put(uint8_t *p, uint32_t v, unsigned n)
{
    for (unsigned i = 0u; i < n; ++i) {
        p[i] = (uint8_t)(v >> (8u * i));
    }
}

/* n bytes at p, least significant first (n <= 4) */
static inline uint32_t br_le_get(const uint8_t *p, unsigned n)
{
    uint32_t v = 0u;
    for (unsigned i = 0u; i < n; ++i) {
        v |= (uint32_t)p[i] << (8u * i);
    }
    return v;
}

/* an f32 as its IEEE 754 binary32 bits */
static inline void br_le_put_f32(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    br_le_put(p, u, 4u);
}

static inline float br_le_get_f32(const uint8_t *p)
{
    const uint32_t u = br_le_get(p, 4u);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

#endif
