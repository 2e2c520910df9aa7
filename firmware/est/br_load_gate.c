/* SPDX-License-Identifier: Apache-2.0 */
/* Glitch or load (docs/modules/est.md, "Glitch or load"): see br_load_gate.h. */
#include "br_load_gate.h"

#include <math.h>

void br_load_gate_reset(br_load_gate_t *g)
{
    g->pend_nu = 0.0f;
    g->pend_k = 0u;
    g->live = 0u;
    g->n_held = 0u;
}

void br_load_gate_tick(br_load_gate_t *g)
{
    if (g->live > 0u) {
        g->live--;
    }
}

/* a force change dF over k periods moves theta by g k^2 dF: within 2 max_N? */
static int within(float nu, float k, float g_radpN, float max_N)
{
    return fabsf(nu / (g_radpN * k * k)) <= 2.0f * max_N;
}

static uint32_t reacquire(br_load_gate_t *g, uint32_t k)
{
    g->pend_nu = 0.0f;
    g->live = BR_LOAD_LIVE_PERIODS;
    return k;
}

uint32_t br_load_gate_gated(br_load_gate_t *g, float nu, uint32_t k0, float g_radpN, float max_N)
{
    /* the periods since the last update: through the held candidate when it was the last measurement */
    const uint32_t k_upd = (g->pend_nu != 0.0f) ? g->pend_k + k0 : k0;
    if (!within(nu, (float)k_upd, g_radpN, max_N)) {
        g->pend_nu = 0.0f; /* no force explains it: an outlier, no candidate */
        return 0u;
    }
    /* a load already changing (re-acquired within the live window): at once, either sign
     * (a cutting-like load's ramps and the compensation's own overshoot; holding those back
     * let the overshoot act a period longer and the correction grew each time: lost lock) */
    if (g->live > 0u) {
        return reacquire(g, k_upd);
    }
    /* the held candidate confirmed: a force change after the last update moved theta by
     * g k1^2 dF at the candidate and g k^2 dF now (k = k1 + k0); a spike comes back
     * (passes the gate), a slip stays (ratio 1): at least half the force's growth,
     * nu / nu_1 >= (k / k1)^2 / 2 (2 for one period each) */
    if (g->pend_nu != 0.0f) {
        const float k1 = (float)g->pend_k, k = (float)k_upd;
        const float grow = (k * k) / (k1 * k1);
        if (nu / g->pend_nu >= 0.5f * grow) {
            return reacquire(g, k_upd);
        }
    }
    /* held: the candidate for the next measurement */
    g->pend_nu = nu;
    g->pend_k = k_upd;
    if (g->n_held < UINT32_MAX) {
        g->n_held++;
    }
    return 0u;
}
