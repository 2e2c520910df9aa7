/* SPDX-License-Identifier: Apache-2.0 */
/* Records the replay stream (target/replay/br_replay.h) from the simulator:
 * the x axis of the thesis circle (--axes 2: both axes, x then y), H-inf + PF
 * at 1.5 ms, m = 1500, for --duration seconds. Per period and axis: the
 * encoder counts the axis read and the reference it was given. --expect also
 * writes the closed loop's own (F_hat, duty) per step and axis as float bits,
 * which the host replay must reproduce.
 *
 *   br_replay_record --out stream.bin [--expect expect.bin] [--duration 1.0] [--axes 1|2] [--ahead L]
 *                    [--delay-id 0|1] [--mslip] [--pf-load Q]
 * --pf-load Q: the PF's shared external force with the random walk Q N^2/s (docs/modules/pf.md;
 * 0: off; default the machine file's)
 * --mslip: the PF's particles carry the hardware-like plant's Maxwell-slip elements
 * (docs/modules/pf.md), in the circle and the stream (on the thesis plant).
 * --ahead: the PF's est.comp_ahead_periods (docs/modules/est.md), in the circle and the stream.
 * --delay-id 0: the PF without the machine's delay identification (est.delay_id,
 * docs/modules/dlyid.md), in the circle and the stream; 1 (default): the machine's. A stream
 * replayed at another m than it was recorded at is no closed loop (the commands change, the
 * counts do not), which the identification may take for a delay: the bench's scaling runs
 * take it off. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "circle/br_circle.h"
#include "replay/br_replay.h"

#define BR_PI 3.14159265358979323846

typedef struct {
    const br_circle_cfg_t *c;
    FILE *steps;   /* temporary: step records */
    FILE *expect;  /* may be NULL */
    uint32_t n;
    uint32_t n_axes;
} rec_t;

static uint32_t f2w(float f)
{
    uint32_t w;
    memcpy(&w, &f, sizeof w);
    return w;
}

/* The reference of axis a (x: phase 0, y: phase pi/2), as sim/lib/circle/br_circle.c computes it. */
static void sink(void *user, const br_circle_sample_t *s)
{
    rec_t *r = user;
    const br_circle_cfg_t *c = r->c;
    const double L = c->plant.lead_mprad, rpc = 2.0 * BR_PI / c->plant.counts_per_rev;
    const double w = 2.0 * BR_PI / c->period_s;
    for (uint32_t a = 0u; a < r->n_axes; a++) {
        const double phase = (a == 0u) ? 0.0 : 0.5 * BR_PI;
        const double x_ref = c->radius_m * sin(w * s->t_s + phase);
        const double counts = x_ref / L / rpc;
        const double whole = floor(counts);
        if (x_ref != s->ref_m[a]) {
            fprintf(stderr, "br_replay_record: reference mismatch at t=%g\n", s->t_s);
            exit(1);
        }
        const uint32_t rec[BR_REPLAY_STEP_WORDS] = {
            (uint32_t)s->counts[a], (uint32_t)(int32_t)whole, f2w((float)(counts - whole)),
            f2w((float)(c->radius_m * w * cos(w * s->t_s + phase) / L))};
        fwrite(rec, sizeof rec, 1, r->steps);
        if (r->expect) {
            const uint32_t e[2] = {f2w((float)s->F_hat_N[a]), f2w((float)s->duty[a])};
            fwrite(e, sizeof e, 1, r->expect);
        }
    }
    r->n++;
}

int main(int argc, char **argv)
{
    const char *out = NULL, *expect = NULL;
    double duration = 1.0;
    uint32_t n_axes = 1u;
    double ahead = 0.0;
    int delay_id = 1;
    int mslip = 0;
    double pf_load = -1.0; /* the machine's */
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
        else if (!strcmp(argv[i], "--expect") && i + 1 < argc) expect = argv[++i];
        else if (!strcmp(argv[i], "--duration") && i + 1 < argc) duration = atof(argv[++i]);
        else if (!strcmp(argv[i], "--axes") && i + 1 < argc) n_axes = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--ahead") && i + 1 < argc) ahead = atof(argv[++i]);
        else if (!strcmp(argv[i], "--delay-id") && i + 1 < argc) delay_id = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--mslip")) mslip = 1;
        else if (!strcmp(argv[i], "--pf-load") && i + 1 < argc) pf_load = atof(argv[++i]);
        else {
            fprintf(stderr, "usage: br_replay_record --out FILE [--expect FILE] [--duration S] [--axes 1|2] "
                            "[--ahead L] [--delay-id 0|1] [--mslip] [--pf-load Q]\n");
            return 2;
        }
    }
    if (out == NULL || !(duration > 0.0) || n_axes < 1u || n_axes > 2u || !(ahead >= 0.0 && ahead <= (double)BR_EST_AHEAD_MAX_PERIODS) ||
        (delay_id != 0 && delay_id != 1) || !(pf_load == -1.0 || (pf_load >= 0.0 && pf_load <= 1.0e9))) {
        fprintf(stderr, "br_replay_record: --out is required, duration > 0, axes 1 or 2, ahead in [0, 2], delay-id 0 or 1, "
                        "pf-load in [0, 1e9]\n");
        return 2;
    }
    br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_PF);
    c.duration_s = duration;
    br_circle_use_ahead(&c, ahead);
    br_circle_use_delay_id(&c, delay_id);
    br_circle_use_pf_mslip(&c, mslip);
    br_circle_use_pf_load(&c, pf_load); /* 0: off; < 0: the machine's */
    rec_t r = {&c, tmpfile(), NULL, 0u, n_axes};
    if (r.steps == NULL) return 1;
    if (expect && (r.expect = fopen(expect, "wb")) == NULL) {
        perror(expect);
        return 1;
    }
    br_circle_result_t res;
    if (br_circle_run(&c, sink, &r, &res) != 0) return 1;

    /* the controller configuration the circle's axes use (br_circle.c axis_init) */
    br_replay_cfg_t rc;
    rc.n_steps = r.n;
    rc.n_axes = n_axes;
    for (int i = 0; i < 3; i++) rc.ctrl.K[i] = c.K[i];
    rc.ctrl.dt_s = (float)c.dt_s;
    rc.ctrl.tau_max_Nm = (float)c.plant.tau_per_duty_Nm;
    rc.ctrl.tau_per_duty_Nm = (float)c.plant.tau_per_duty_Nm;
    rc.ctrl.rad_per_count = (float)(2.0 * BR_PI / c.plant.counts_per_rev);
    rc.ctrl.lead_mprad = (float)c.plant.lead_mprad;
    rc.pf = c.pf;
    uint32_t hdr[BR_REPLAY_HDR_WORDS];
    br_replay_hdr_encode(&rc, hdr);
    FILE *f = fopen(out, "wb");
    if (f == NULL) {
        perror(out);
        return 1;
    }
    fwrite(hdr, sizeof hdr, 1, f);
    rewind(r.steps);
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, r.steps)) > 0) fwrite(buf, 1, n, f);
    if (fclose(f) != 0 || (r.expect && fclose(r.expect) != 0)) return 1;
    fclose(r.steps);
    printf("br_replay_record: %u steps (%.3f s at %.4g s, m = %u, %u axes) -> %s\n", r.n, duration, c.dt_s,
           c.pf.n_particles, n_axes, out);
    return 0;
}
