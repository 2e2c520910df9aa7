/* SPDX-License-Identifier: Apache-2.0 */
/* UKF bench image for QEMU's mps2 boards (docs/target.md, "The UKF on both
 * cores"): the STM32G4 image's application (H-inf + UKF at the control
 * period, the machine's tuned settings, hal/stm32g4/image/main.c) run for
 * BR_UKF_BENCH_STEPS periods on the circle reference, each br_app_step timed
 * with SysTick as the replay image does (calibrated, `-icount shift=0`).
 * The encoder reads a small float plant closing the loop (the machine's
 * inertia, viscous and smoothed Coulomb friction, 10 Euler substeps per
 * period): consistent data, so no guard trips; the UKF's work per step (its
 * sigma points through the model, a Cholesky factor) does not depend on it.
 *
 *   qemu-system-arm -M mps2-an386 -nographic -icount shift=0 \
 *     -semihosting-config enable=on,target=native -kernel br_ukf_bench_mps2.elf
 *
 * Prints "calib insns=... ticks=..." and "ukf steps=... sum_ticks=...
 * max_ticks=... sizeof_ukf=..."; exit status 0, or 1 on a failed step. */
#include <math.h>
#include <stdint.h>

#include "br_semihost.h"
#include "bristle/br_app.h"
#include "bristle/br_machine_cfg.h"
#include "bristle/br_refgen.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"

#define BR_SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define BR_SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define BR_SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define BR_CAL_ITER 1000000u
#define BR_UKF_BENCH_STEPS 2000u
#define BR_UKF_BENCH_DT_S BR_MACHINE_CTRL_PERIOD_S_F
#define BR_UKF_BENCH_SUBSTEPS 10u

typedef struct {
    int32_t counts;
    float duty;
    float theta_rad;  /* the plant: motor angle and speed */
    float omega_radps;
} bench_hal_t;

/* J_eff w' = tau - L (sigma2 L w + Fc v / (|v| + vs)), v = L w; explicit Euler */
static void plant_period(bench_hal_t *p)
{
    const float L = BR_MACHINE_LEAD_MPRAD_F;
    const float jeff = BR_MACHINE_J_KGM2_F + BR_MACHINE_M_KG_F * L * L;
    const float h = BR_UKF_BENCH_DT_S / (float)BR_UKF_BENCH_SUBSTEPS;
    const float tau = p->duty * BR_MACHINE_TAU_PER_DUTY_NM_F;
    for (uint32_t i = 0u; i < BR_UKF_BENCH_SUBSTEPS; ++i) {
        const float v = L * p->omega_radps;
        const float f = BR_MACHINE_SIGMA2_NSPM_F * v + BR_MACHINE_FC_N_F * v / (fabsf(v) + BR_MACHINE_VS_MPS_F);
        p->theta_rad += h * p->omega_radps;
        p->omega_radps += h * (tau - L * f) / jeff;
    }
    p->counts = (int32_t)floorf(p->theta_rad / BR_MACHINE_RAD_PER_COUNT_F + 0.5f);
}

static br_status_t enc_read(void *ctx, int32_t *counts)
{
    *counts = ((bench_hal_t *)ctx)->counts;
    return BR_OK;
}

static br_status_t pwm_write(void *ctx, float duty)
{
    ((bench_hal_t *)ctx)->duty = duty;
    return BR_OK;
}

static br_status_t tick_wait(void *ctx, uint32_t *tick)
{
    (void)ctx;
    *tick = 0u;
    return BR_OK;
}

/* 24-bit SysTick down-counter as an up-count (stamps < 2^24 ticks apart). */
static uint32_t stamp(uint32_t *last_raw, uint32_t *ext)
{
    const uint32_t raw = BR_SYST_CVR & 0xFFFFFFu;
    *ext += (*last_raw - raw) & 0xFFFFFFu;
    *last_raw = raw;
    return *ext;
}

static void say_u32(const char *label, uint32_t v)
{
    char t[11];
    char b[12];
    int n = 0;
    int i = 0;
    do {
        t[n++] = (char)('0' + (char)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    while (n > 0) b[i++] = t[--n];
    b[i] = '\0';
    br_sh_puts(label);
    br_sh_puts(b);
}

static const br_ctrl_cfg_t bench_ctrl = BR_MACHINE_CTRL_CFG(BR_UKF_BENCH_DT_S);

static const br_ukf_cfg_t bench_ukf_cfg = BR_MACHINE_UKF_CFG_TUNED(BR_UKF_BENCH_DT_S);

static const br_refgen_cfg_t bench_ref = {
    .amplitude_m = 5.0e-3f,
    .period_s = 2.0f,
    .phase_rad = 0.0f,
    .dt_s = BR_UKF_BENCH_DT_S,
    .lead_mprad = BR_MACHINE_LEAD_MPRAD_F,
    .rad_per_count = BR_MACHINE_RAD_PER_COUNT_F,
};

int main(void)
{
    bench_hal_t io = {0, 0.0f, 0.0f, 0.0f};
    const br_hal_t hal = {&io, enc_read, pwm_write, tick_wait, 0, 0};
    br_ukf_t ukf;
    br_app_t app;
    br_refgen_t refgen;
    br_ref_t ref = {0, 0.0f, 0.0f};
    const br_app_cfg_t cfg = {
        .ctrl = &bench_ctrl,
        .est = BR_APP_EST_UKF,
        .ukf = &bench_ukf_cfg,
        .guard = br_app_guard_cfg(BR_UKF_BENCH_DT_S, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F),
        .motion = br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE),
    };
    const br_app_mem_t mem = {.ukf = &ukf};
    uint32_t last_raw;
    uint32_t ext = 0u;
    uint32_t sum = 0u;
    uint32_t max = 0u;

    BR_SYST_RVR = 0xFFFFFFu;
    BR_SYST_CVR = 0u;
    BR_SYST_CSR = 0x5u; /* processor clock, enabled, no interrupt */
    last_raw = BR_SYST_CVR & 0xFFFFFFu;
    const uint32_t c0 = stamp(&last_raw, &ext);
    {
        register uint32_t n __asm__("r4") = BR_CAL_ITER;
        __asm__ volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc");
    }
    const uint32_t c1 = stamp(&last_raw, &ext);
    say_u32("calib insns=", 2u * BR_CAL_ITER);
    say_u32(" ticks=", c1 - c0);
    br_sh_puts("\n");

    if (br_refgen_init(&refgen, &bench_ref) != BR_OK || br_app_init(&app, &cfg, &hal, &mem) != BR_OK ||
        br_app_arm(&app) != BR_OK) {
        br_sh_puts("ukf bench: init failed\n");
        br_sh_exit(1u);
    }
    for (uint32_t k = 0u; k < BR_UKF_BENCH_STEPS; ++k) {
        plant_period(&io); /* the axis under the last period's duty */
        if (br_refgen_step(&refgen, &ref) != BR_OK) {
            br_sh_puts("ukf bench: reference failed\n");
            br_sh_exit(1u);
        }
        const uint32_t t0 = stamp(&last_raw, &ext);
        const br_status_t st = br_app_step(&app, &ref);
        const uint32_t dt = stamp(&last_raw, &ext) - t0;
        if (BR_FAILED(st)) {
            say_u32("ukf bench: step failed at k=", k);
            say_u32(" fault=", (uint32_t)app.fault);
            br_sh_puts("\n");
            br_sh_exit(1u);
        }
        if (k > 0u) { /* step 0 primes the filter */
            sum += dt;
            max = (dt > max) ? dt : max;
        }
    }
    say_u32("ukf steps=", BR_UKF_BENCH_STEPS - 1u);
    say_u32(" sum_ticks=", sum);
    say_u32(" max_ticks=", max);
    say_u32(" sizeof_ukf=", (uint32_t)sizeof ukf);
    br_sh_puts("\n");
    br_sh_exit(0u);
}
