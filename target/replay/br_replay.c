/* SPDX-License-Identifier: Apache-2.0 */
/* Replay core (br_replay.h): portable C99, no libc I/O, no globals. */
#include "br_replay.h"

#include <string.h>

#include "bristle_gen/est/br_noise_table.h"
#include "bristle_gen/machine/br_machine.h"
#include "bristle/br_machine_cfg.h"

static uint32_t f2w(float f)
{
    uint32_t w;
    memcpy(&w, &f, sizeof w);
    return w;
}

static float w2f(uint32_t w)
{
    float f;
    memcpy(&f, &w, sizeof f);
    return f;
}

void br_replay_hdr_encode(const br_replay_cfg_t *c, uint32_t w[BR_REPLAY_HDR_WORDS])
{
    uint32_t i = 0u;
    const br_model_cfg_t *m = &c->pf.est.model;
    w[i++] = BR_REPLAY_MAGIC;
    w[i++] = (c->n_axes == 2u) ? BR_REPLAY_VERSION_XY : BR_REPLAY_VERSION;
    w[i++] = c->n_steps;
    for (uint32_t j = 0u; j < 3u; ++j) w[i++] = f2w(c->ctrl.K[j]);
    w[i++] = f2w(c->ctrl.dt_s);
    w[i++] = f2w(c->ctrl.tau_max_Nm);
    w[i++] = f2w(c->ctrl.tau_per_duty_Nm);
    w[i++] = f2w(c->ctrl.rad_per_count);
    w[i++] = f2w(c->ctrl.lead_mprad);
    w[i++] = f2w(m->J_kgm2);
    w[i++] = f2w(m->M_kg);
    w[i++] = f2w(m->lead_mprad);
    w[i++] = f2w(m->sigma2_Nspm);
    w[i++] = f2w(m->lugre.sigma0_Npm);
    w[i++] = f2w(m->lugre.sigma1_Nspm);
    w[i++] = f2w(m->lugre.Fc_N);
    w[i++] = f2w(m->lugre.Fs_N);
    w[i++] = f2w(m->lugre.vs_mps);
    w[i++] = f2w(m->dt_s);
    w[i++] = c->pf.n_particles;
    for (uint32_t j = 0u; j < BR_NX; ++j) w[i++] = f2w(c->pf.est.q_var[j]);
    w[i++] = f2w(c->pf.est.r_var_rad2);
    w[i++] = f2w(c->pf.est.gp0_N);
    for (uint32_t j = 0u; j < BR_NX; ++j) w[i++] = f2w(c->pf.x0_std[j]);
    w[i++] = f2w(c->pf.est.gp_min_N);
    w[i++] = f2w(c->pf.est.gp_max_N);
    w[i++] = f2w(c->pf.est.outlier_sigma);
    w[i++] = c->pf.est.reanchor_after;
    w[i++] = f2w(c->pf.est.rad_per_count);
    w[i++] = c->pf.noise_len;
    w[i++] = c->pf.noise_skip;
    /* cfg.adapt (a stream without these words has zeros there: adapt off) */
    w[i++] = f2w(c->pf.adapt.nis_ref);
    w[i++] = f2w(c->pf.adapt.alpha);
    w[i++] = f2w(c->pf.adapt.max_scale);
    /* cfg.est.comp_ahead_periods (zero in a stream without it: the filtered estimate) */
    w[i++] = f2w(c->pf.est.comp_ahead_periods);
    /* cfg.est.delay_id (zeros in a stream without them: off) */
    w[i++] = c->pf.est.delay_id.n_cand;
    w[i++] = f2w(c->pf.est.delay_id.step_s);
    w[i++] = f2w(c->pf.est.delay_id.q_force_N2ps);
    w[i++] = f2w(c->pf.est.delay_id.memory_s);
    w[i++] = f2w(c->pf.est.delay_id.warmup_s);
    w[i++] = f2w(c->pf.est.delay_id.switch_ratio);
    /* the Maxwell-slip elements (zeros in a stream without them: the thesis's LuGre) */
    w[i++] = (uint32_t)m->mslip.n;
    for (uint32_t j = 0u; j < BR_MSLIP_MAX; ++j) w[i++] = f2w(m->mslip.k_Npm[j]);
    for (uint32_t j = 0u; j < BR_MSLIP_MAX; ++j) w[i++] = f2w(m->mslip.share[j]);
    w[i++] = f2w(m->mslip.sigma2_Nspm);
    /* cfg.est.outlier_transient_rad (zero in a stream without it: the thesis gate) */
    w[i++] = f2w(c->pf.est.outlier_transient_rad);
    /* cfg.load (zeros in a stream without them: off) */
    w[i++] = f2w(c->pf.load.q_N2);
    w[i++] = f2w(c->pf.load.max_N);
    /* cfg.est.delay_id's steady phase (zeros in a stream without them: one phase) */
    w[i++] = f2w(c->pf.est.delay_id.steady_after_s);
    w[i++] = f2w(c->pf.est.delay_id.steady_memory_s);
    w[i++] = f2w(c->pf.est.delay_id.steady_switch_ratio);
    while (i < BR_REPLAY_HDR_WORDS) w[i++] = 0u;
}

br_status_t br_replay_hdr_decode(const uint32_t w[BR_REPLAY_HDR_WORDS], br_replay_cfg_t *c)
{
    uint32_t i = 0u;
    br_model_cfg_t *m = &c->pf.est.model;
    if (w[i++] != BR_REPLAY_MAGIC) return BR_E_PARAM;
    const uint32_t version = w[i++];
    if (version != BR_REPLAY_VERSION && version != BR_REPLAY_VERSION_XY) return BR_E_PARAM;
    c->n_axes = (version == BR_REPLAY_VERSION_XY) ? 2u : 1u;
    c->n_steps = w[i++];
    for (uint32_t j = 0u; j < 3u; ++j) c->ctrl.K[j] = w2f(w[i++]);
    c->ctrl.dt_s = w2f(w[i++]);
    c->ctrl.tau_max_Nm = w2f(w[i++]);
    c->ctrl.tau_per_duty_Nm = w2f(w[i++]);
    c->ctrl.rad_per_count = w2f(w[i++]);
    c->ctrl.lead_mprad = w2f(w[i++]);
    m->J_kgm2 = w2f(w[i++]);
    m->M_kg = w2f(w[i++]);
    m->lead_mprad = w2f(w[i++]);
    m->sigma2_Nspm = w2f(w[i++]);
    m->lugre.sigma0_Npm = w2f(w[i++]);
    m->lugre.sigma1_Nspm = w2f(w[i++]);
    m->lugre.Fc_N = w2f(w[i++]);
    m->lugre.Fs_N = w2f(w[i++]);
    m->lugre.vs_mps = w2f(w[i++]);
    m->dt_s = w2f(w[i++]);
    m->causes = (br_causes_t){0}; /* the stream's model is the thesis model */
    c->pf.n_particles = w[i++];
    for (uint32_t j = 0u; j < BR_NX; ++j) c->pf.est.q_var[j] = w2f(w[i++]);
    c->pf.est.r_var_rad2 = w2f(w[i++]);
    c->pf.est.gp0_N = w2f(w[i++]);
    for (uint32_t j = 0u; j < BR_NX; ++j) c->pf.x0_std[j] = w2f(w[i++]);
    c->pf.est.gp_min_N = w2f(w[i++]);
    c->pf.est.gp_max_N = w2f(w[i++]);
    c->pf.est.outlier_sigma = w2f(w[i++]);
    c->pf.est.reanchor_after = w[i++];
    c->pf.est.rad_per_count = w2f(w[i++]);
    c->pf.noise_len = w[i++];
    c->pf.noise_skip = w[i++];
    c->pf.adapt.nis_ref = w2f(w[i++]);
    c->pf.adapt.alpha = w2f(w[i++]);
    c->pf.adapt.max_scale = w2f(w[i++]);
    c->pf.est.comp_ahead_periods = w2f(w[i++]);
    c->pf.est.delay_id.n_cand = w[i++];
    c->pf.est.delay_id.step_s = w2f(w[i++]);
    c->pf.est.delay_id.q_force_N2ps = w2f(w[i++]);
    c->pf.est.delay_id.memory_s = w2f(w[i++]);
    c->pf.est.delay_id.warmup_s = w2f(w[i++]);
    c->pf.est.delay_id.switch_ratio = w2f(w[i++]);
    /* n beyond BR_MSLIP_MAX is refused by br_pf_init (br_mslip_cfg_check) */
    const uint32_t n_el = w[i++];
    m->mslip.n = (n_el <= (uint32_t)BR_MSLIP_MAX) ? (int)n_el : BR_MSLIP_MAX + 1;
    for (uint32_t j = 0u; j < BR_MSLIP_MAX; ++j) m->mslip.k_Npm[j] = w2f(w[i++]);
    for (uint32_t j = 0u; j < BR_MSLIP_MAX; ++j) m->mslip.share[j] = w2f(w[i++]);
    m->mslip.sigma2_Nspm = w2f(w[i++]);
    c->pf.est.outlier_transient_rad = w2f(w[i++]);
    c->pf.load.q_N2 = w2f(w[i++]);
    c->pf.load.max_N = w2f(w[i++]);
    c->pf.est.delay_id.steady_after_s = w2f(w[i++]);
    c->pf.est.delay_id.steady_memory_s = w2f(w[i++]);
    c->pf.est.delay_id.steady_switch_ratio = w2f(w[i++]);
    if (c->pf.noise_len != BR_NOISE_LEN) return BR_E_PARAM;
    c->pf.noise = br_noise_table;
    return BR_OK;
}

uint32_t br_replay_idx_hash(const uint16_t *idx, uint32_t m)
{
    uint32_t h = BR_REPLAY_FNV_OFFSET;
    for (uint32_t i = 0u; i < m; ++i) {
        h = (h ^ (uint32_t)(idx[i] & 0xFFu)) * BR_REPLAY_FNV_PRIME;
        h = (h ^ (uint32_t)(idx[i] >> 8)) * BR_REPLAY_FNV_PRIME;
    }
    return h;
}

static br_status_t enc_read(void *ctx, int32_t *counts)
{
    *counts = ((const br_replay_axis_t *)ctx)->enc_counts;
    return BR_OK;
}

static br_status_t pwm_write(void *ctx, float duty)
{
    ((br_replay_axis_t *)ctx)->duty = duty;
    return BR_OK;
}

static br_status_t tick_wait(void *ctx, uint32_t *tick)
{
    (void)ctx;
    *tick = 0u;
    return BR_OK;
}

int br_replay_run(br_replay_t *r, const br_replay_io_t *io, uint32_t n_particles_override, uint32_t scalar_path)
{
    uint32_t hdr[BR_REPLAY_HDR_WORDS];
    if (io->read(io->ctx, hdr, (uint32_t)sizeof hdr) != 0) return -1;
    if (br_replay_hdr_decode(hdr, &r->cfg) != BR_OK) return -2;
    if (n_particles_override != 0u) r->cfg.pf.n_particles = n_particles_override;
    r->cfg.pf.scalar_path = scalar_path;
    const uint32_t na = r->cfg.n_axes;
    const br_app_cfg_t app_cfg = {&r->cfg.ctrl, BR_APP_EST_PF, &r->cfg.pf, NULL, NULL,
                                 br_app_guard_cfg(r->cfg.ctrl.dt_s, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F),
                                 br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE)};
    for (uint32_t a = 0u; a < na; ++a) {
        br_replay_axis_t *x = &r->ax[a];
        x->hal.ctx = x;
        x->hal.encoder_read = enc_read;
        x->hal.pwm_write = pwm_write;
        x->hal.tick_wait = tick_wait;
        x->hal.pwm_disable = NULL;
        x->hal.pwm_enable = NULL;
        x->duty = 0.0f;
        const br_app_mem_t mem = {&x->pf, NULL};
        /* the replay arms right after init, as the simulator */
        if (br_app_init(&x->app, &app_cfg, &x->hal, &mem) != BR_OK || br_app_arm(&x->app) != BR_OK) return -3;
    }
    for (uint32_t k = 0u; k < r->cfg.n_steps; ++k) {
        uint32_t in[BR_REPLAY_MAX_AXES][BR_REPLAY_STEP_WORDS];
        if (io->read(io->ctx, in, (uint32_t)(na * sizeof in[0])) != 0) return -1;
        /* the axes one after the other in the period, as on one MCU; each
         * axis's end is stamped as it ends, and the outputs (index hash,
         * write) of all axes are made after the last has stepped, so that
         * the period's cost holds the axes' br_app_step only (the inputs are
         * unpacked before the period's first stamp) */
        br_ref_t ref[BR_REPLAY_MAX_AXES];
        br_status_t st[BR_REPLAY_MAX_AXES];
        uint32_t t1[BR_REPLAY_MAX_AXES];
        for (uint32_t a = 0u; a < na; ++a) {
            r->ax[a].enc_counts = (int32_t)in[a][0];
            ref[a] = (br_ref_t){(int32_t)in[a][1], w2f(in[a][2]), w2f(in[a][3])};
        }
        uint32_t n_run = 0u; /* axes stepped: a failed step ends the period, as it ends the replay */
        int failed = 0;
        const uint32_t t0 = io->stamp ? io->stamp(io->ctx) : 0u;
        for (uint32_t a = 0u; a < na && !failed; ++a) {
            st[a] = br_app_step(&r->ax[a].app, &ref[a]);
            t1[a] = io->stamp ? io->stamp(io->ctx) : 0u;
            n_run = a + 1u;
            failed = BR_FAILED(st[a]);
        }
        for (uint32_t a = 0u; a < n_run; ++a) {
            const br_replay_axis_t *x = &r->ax[a];
            uint32_t out[BR_REPLAY_OUT_WORDS];
            out[0] = k;
            out[1] = (uint32_t)(int32_t)st[a];
            out[2] = br_replay_idx_hash(x->pf.idx, r->cfg.pf.n_particles);
            out[3] = f2w(x->app.F_hat_N);
            out[4] = f2w(x->duty);
            out[5] = t1[a] - t0;
            if (io->write(io->ctx, out, (uint32_t)sizeof out) != 0) return -1;
        }
        if (failed) return -4;
    }
    return 0;
}
