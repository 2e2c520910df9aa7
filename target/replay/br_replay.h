/* SPDX-License-Identifier: Apache-2.0 */
/* Replay of a recorded stream through the application (br_app_step with the
 * PF), identical on the host and on the Cortex-M7 (target/mps2 image under
 * QEMU). docs/target.md.
 *
 * Stream (little-endian 32-bit words, both hosts and the M7 are LE):
 *   header  BR_REPLAY_HDR_WORDS words: magic, version, n_steps, then the
 *           controller configuration (8 floats) and the PF configuration
 *           (model 10 floats, m, q_var[4], r, gp0, x0_std[4], gp_min, gp_max,
 *           outlier_sigma, reanchor_after, rad_per_count, noise_len, noise_skip,
 *           adapt.nis_ref, adapt.alpha, adapt.max_scale; zeros there: adapt off;
 *           est.comp_ahead_periods; zero there: no lead; est.delay_id's
 *           n_cand, step_s, q_force_N2ps, memory_s, warmup_s, switch_ratio;
 *           zeros there: off; the model's Maxwell-slip elements: n,
 *           k_Npm[BR_MSLIP_MAX], share[BR_MSLIP_MAX], sigma2; zeros there: LuGre;
 *           est.outlier_transient_rad; zero there: the thesis gate; the
 *           shared external force's load.q_N2, load.max_N; zeros there: off;
 *           est.delay_id's steady phase: steady_after_s, steady_memory_s,
 *           steady_switch_ratio; zeros there: one phase),
 *           floats as their bit patterns, so every value is exact;
 *   steps   n_steps records of 4 words per axis: encoder counts (int32),
 *           reference counts (int32), reference fraction (float), reference
 *           omega (float). Version 1: one axis; version 2: two axes (x, y of
 *           the X-Y table, each with its own application and PF, one after
 *           the other in the same period, as two axes on one MCU).
 * Output: one record of BR_REPLAY_OUT_WORDS words per step and axis: k, status,
 *   FNV-1a hash of the PF's m uint16 resampling indices (little-endian bytes),
 *   F_hat (float bits), duty (float bits), cost (stamp difference from the
 *   start of the period to the end of this axis's br_app_step, so the last
 *   axis's record holds the whole period; 0 when the I/O has no stamp; not
 *   compared). A period's records (index hashes, writes) are made after its
 *   last axis has stepped, so that its cost is the axes' br_app_step only.
 * The PF's noise table is the firmware's br_noise_table; noise_len must match. */
#ifndef BR_REPLAY_H
#define BR_REPLAY_H

#include <stdint.h>

#include "bristle/br_app.h"

#define BR_REPLAY_MAGIC 0x53525242u /* "BRRS" */
#define BR_REPLAY_VERSION 1u   /* one axis */
#define BR_REPLAY_VERSION_XY 2u /* two axes */
#define BR_REPLAY_MAX_AXES 2u
#define BR_REPLAY_HDR_WORDS 73u
#define BR_REPLAY_STEP_WORDS 4u
#define BR_REPLAY_OUT_WORDS 6u
#define BR_REPLAY_FNV_OFFSET 2166136261u
#define BR_REPLAY_FNV_PRIME 16777619u

typedef struct {
    uint32_t n_steps;
    br_ctrl_cfg_t ctrl;
    br_pf_cfg_t pf; /* noise = br_noise_table */
    uint32_t n_axes; /* 1 or 2 (the header's version); both axes share ctrl and pf */
} br_replay_cfg_t;

/* I/O supplied by the platform: read/write exactly n bytes (return 0 on
 * success), and an optional free-running 32-bit up-counter (stamp may be NULL). */
typedef struct {
    void *ctx;
    int (*read)(void *ctx, void *buf, uint32_t n);
    int (*write)(void *ctx, const void *buf, uint32_t n);
    uint32_t (*stamp)(void *ctx);
} br_replay_io_t;

/* One axis: its application, PF and HAL binding. */
typedef struct {
    br_pf_t pf;   /* the application's estimator storage */
    br_app_t app;
    br_hal_t hal;
    int32_t enc_counts; /* this step's recorded encoder reading */
    float duty;         /* last duty written by the application */
} br_replay_axis_t;

/* All replay state: two axes of ~62 KB with the PF. The caller owns it
 * (host: heap, target: main's stack). */
typedef struct {
    br_replay_cfg_t cfg;
    br_replay_axis_t ax[BR_REPLAY_MAX_AXES];
} br_replay_t;

/* Header encode/decode (the recorder uses the encoder). */
void br_replay_hdr_encode(const br_replay_cfg_t *cfg, uint32_t w[BR_REPLAY_HDR_WORDS]);
br_status_t br_replay_hdr_decode(const uint32_t w[BR_REPLAY_HDR_WORDS], br_replay_cfg_t *cfg);

/* FNV-1a over the m indices as little-endian uint16. */
uint32_t br_replay_idx_hash(const uint16_t *idx, uint32_t m);

/* Reads the header and every step from io, runs br_app_step per step and
 * writes the output records. n_particles_override != 0 replaces the stream's m;
 * scalar_path selects the PF's scalar reference path (br_pf_cfg_t.scalar_path).
 * Returns 0, or a negative code: -1 I/O, -2 bad header, -3 init failed,
 * -4 a step failed with a status other than BR_OK / a warning (the later
 * axes of that period are not stepped; the records of the axes that were,
 * the failed one's last, are written first). */
int br_replay_run(br_replay_t *r, const br_replay_io_t *io, uint32_t n_particles_override, uint32_t scalar_path);

#endif
