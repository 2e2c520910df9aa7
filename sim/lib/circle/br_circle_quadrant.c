/* SPDX-License-Identifier: Apache-2.0 */
/* The quadrant glitch of a circle: br_circle_quadrant.h. */
#include "br_circle_quadrant.h"

#include <math.h>

typedef struct {
    double period_s;
    double sum2;
    long n;
} quad_acc_t;

static void quad_sink(void *user, const br_circle_sample_t *s)
{
    quad_acc_t *q = user;
    /* time since the last quarter period, in periods; the start (k = 0) is no reversal */
    const double quarters = s->t_s / (0.25 * q->period_s);
    const double k = floor(quarters);
    if (k >= 1.0 && (quarters - k) * 0.25 < BR_QUADRANT_WINDOW_T) {
        q->sum2 += s->radial_err_m * s->radial_err_m;
        q->n++;
    }
}

int br_circle_quadrant_run(const br_circle_cfg_t *cfg, br_quadrant_result_t *res)
{
    quad_acc_t q = {cfg->period_s, 0.0, 0};
    const int rc = br_circle_run(cfg, quad_sink, &q, &res->run);
    res->n_quadrant = q.n;
    res->quadrant_rms_m = (rc == 0 && q.n > 0) ? sqrt(q.sum2 / (double)q.n) : NAN;
    return rc;
}
