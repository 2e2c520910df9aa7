/* SPDX-License-Identifier: Apache-2.0 */
/* Sinusoidal axis reference with a Q0.64 phase accumulator, float32.
 * See bristle/br_refgen.h and docs/modules/refgen.md. */
#include "bristle/br_refgen.h"

#include <math.h>
#include <stddef.h>

#define BR_REFGEN_TWO_PI_F 6.28318530717958647692f
#define BR_REFGEN_TWO_POW64_F 0x1p64f
/* 2 pi = HI + LO: HI is the float nearest 2 pi, LO the remainder. */
#define BR_REFGEN_TWO_PI_HI_F 6.28318548202514648438f
#define BR_REFGEN_TWO_PI_LO_F -1.74845553146951557e-7f

static int br_refgen_finite_pos(float v)
{
    return isfinite(v) && v > 0.0f;
}

/* Two's complement reinterpretation without implementation-defined casts. */
static int32_t br_refgen_u32_to_i32(uint32_t u)
{
    return (u <= (uint32_t)INT32_MAX) ? (int32_t)u : -(int32_t)(~u) - 1;
}

/* floor(m) for 0 <= m < 2^64 as uint64, through two exact 32-bit halves:
 * float -> 64-bit integer conversions would pull in soft-double helpers. */
static uint64_t br_refgen_u64_from_float(float m)
{
    float mh = floorf(m * 0x1p-32f);   /* < 2^32, an integer with <= 24 bits */
    float ml = m - mh * 0x1p32f;       /* exact, in [0, 2^32) */
    return ((uint64_t)(uint32_t)mh << 32) + (uint64_t)(uint32_t)ml;
}

/* Turns per step dt/T as Q0.64. q1 = RN(dt/T) carries 24 bits; the rounding
 * remainder dt - q1 T is exact through one fused multiply-add, and its
 * quotient q2 adds the next 24 bits: dt/T = q1 + q2 to ~2^-47 relative.
 * Needs dt/T <= 1/2 (checked by the caller) so that q1 2^64 < 2^64. */
static uint64_t br_refgen_turns_q64(float dt_s, float period_s)
{
    float q1 = dt_s / period_s;
    float rem = fmaf(-q1, period_s, dt_s);
    float q2 = rem / period_s;
    uint64_t hi = br_refgen_u64_from_float(q1 * BR_REFGEN_TWO_POW64_F);
    uint64_t lo = br_refgen_u64_from_float(fabsf(q2) * BR_REFGEN_TWO_POW64_F);
    return (q2 >= 0.0f) ? hi + lo : hi - lo;
}

/* An angle in rad (any finite value) as a fraction of a turn in Q0.64.
 * Whole turns are removed first against 2 pi split in two floats
 * (hi + lo, Cody-Waite, each product fused), so a large initial phase keeps
 * the accuracy of its own float representation. */
static uint64_t br_refgen_angle_q64(float phase_rad)
{
    float n = floorf(phase_rad * (1.0f / BR_REFGEN_TWO_PI_F));
    float r = fmaf(-n, BR_REFGEN_TWO_PI_HI_F, phase_rad);
    float t;
    r = fmaf(-n, BR_REFGEN_TWO_PI_LO_F, r);
    t = r / BR_REFGEN_TWO_PI_F;
    t = t - floorf(t);
    if (!(t >= 0.0f && t < 1.0f)) {
        t = 0.0f; /* t - floor(t) rounded up to 1 for a tiny negative t */
    }
    return br_refgen_u64_from_float(t * BR_REFGEN_TWO_POW64_F);
}

br_status_t br_refgen_init(br_refgen_t *g, const br_refgen_cfg_t *cfg)
{
    float steps;
    float amp_rad;
    float amp_counts;
    float amp_radps;

    if (g == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    g->ready = 0;
    if (!br_refgen_finite_pos(cfg->amplitude_m) || !br_refgen_finite_pos(cfg->period_s) ||
        !br_refgen_finite_pos(cfg->dt_s) || !br_refgen_finite_pos(cfg->lead_mprad) ||
        !br_refgen_finite_pos(cfg->rad_per_count) || !isfinite(cfg->phase_rad)) {
        return BR_E_PARAM;
    }
    steps = cfg->period_s / cfg->dt_s;
    if (!(steps >= 2.0f && steps <= BR_REFGEN_STEPS_PER_PERIOD_MAX)) {
        return BR_E_PARAM;
    }
    amp_rad = cfg->amplitude_m / cfg->lead_mprad;
    amp_counts = amp_rad / cfg->rad_per_count;
    amp_radps = amp_rad * (BR_REFGEN_TWO_PI_F / cfg->period_s);
    if (!isfinite(amp_counts) || amp_counts > BR_REFGEN_AMP_COUNTS_MAX || !br_refgen_finite_pos(amp_radps)) {
        return BR_E_PARAM;
    }
    g->cfg = *cfg;
    g->amp_counts = amp_counts;
    g->amp_radps = amp_radps;
    g->dphase_q64 = br_refgen_turns_q64(cfg->dt_s, cfg->period_s);
    g->phase_q64 = br_refgen_angle_q64(cfg->phase_rad);
    g->ready = 1;
    return BR_OK;
}

br_status_t br_refgen_step(br_refgen_t *g, br_ref_t *ref)
{
    int32_t turn_i32;
    float ang;
    float counts;
    float whole;
    float frac;

    if (g == NULL || ref == NULL) {
        return BR_E_NULL;
    }
    if (!g->ready) {
        return BR_E_STATE;
    }
    /* Angle in [-pi, pi]: the top 32 bits of the phase read as a signed turn
     * fraction (2^32 = one turn); the int -> float conversion keeps float's
     * relative precision, so small angles stay finer than 2^-24 turn. */
    turn_i32 = br_refgen_u32_to_i32((uint32_t)(g->phase_q64 >> 32));
    ang = (float)turn_i32 * (BR_REFGEN_TWO_PI_F / 4294967296.0f);

    counts = g->amp_counts * sinf(ang);
    whole = floorf(counts);
    frac = counts - whole; /* exact, in [0, 1) */
    if (frac >= 1.0f) {
        frac = 0.0f;
        whole += 1.0f;
    }
    ref->ref_counts = (int32_t)whole; /* |whole| <= 2^30 */
    ref->ref_frac_counts = frac;
    ref->ref_omega_radps = g->amp_radps * cosf(ang);

    g->phase_q64 += g->dphase_q64; /* wraps modulo one turn */
    return BR_OK;
}

float br_refgen_phase_rad(const br_refgen_t *g)
{
    uint32_t top24;

    if (g == NULL || !g->ready) {
        return 0.0f;
    }
    /* Top 24 bits convert exactly; (2^24 - 1) 2 pi / 2^24 rounds below 2 pi. */
    top24 = (uint32_t)(g->phase_q64 >> 40);
    return (float)top24 * (BR_REFGEN_TWO_PI_F / 16777216.0f);
}
