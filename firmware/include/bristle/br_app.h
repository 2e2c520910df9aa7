/* SPDX-License-Identifier: Apache-2.0 */
/* The application: one control period of one axis, the only place where the
 * pieces are wired together. A configuration names the controller and the
 * friction estimator; br_app_step then runs
 *
 *   encoder -> estimator (PF, UKF or none) -> controller (eq. 7, the estimate
 *   as compensation) -> PWM
 *
 * over the HAL the caller binds: the one home of the control period. The
 * production images (hal/stm32/image, one for every STM32 board), the replay image
 * (target/mps2) and the simulator's circle experiment (sim/lib/circle) all run
 * br_app_step. docs/modules/app.md.
 *
 * Where the estimator's state lives: in storage the caller provides
 * (br_app_mem_t), not in a union inside br_app_t. A union would make every
 * br_app_t as large as br_pf_t (~94 KB at BR_PF_MAX_PARTICLES): the
 * H-infinity-only image, whose whole state sits in a 16 KiB stack, would
 * carry 94 KB it never uses, and a UKF application (696 B of filter) too.
 * With caller storage each program sizes and places exactly its estimator:
 * on the MCU a static br_pf_t in a RAM section (.bss in the DTCM, never the
 * stack), on the host the heap. br_app_t itself is small (the controller, the
 * estimator interface, the guards' state). */
#ifndef BR_APP_H
#define BR_APP_H

#include "bristle/br_ctrl.h"
#include "bristle/br_est.h"
#include "bristle/br_hal.h"
#include "bristle/br_pf.h"
#include "bristle/br_ref.h"
#include "bristle/br_ukf.h"

typedef enum {
    BR_APP_EST_NONE = 0,  /* no compensation: H-infinity only */
    BR_APP_EST_PF = 1,    /* particle filter, cfg->pf, state in mem->pf */
    BR_APP_EST_UKF = 2,   /* unscented Kalman filter, cfg->ukf, state in mem->ukf */
    BR_APP_EST_EXTERN = 3 /* an estimator the caller runs behind br_est_t (cfg->ext, its
                             predict and reset may be NULL): the simulator's true-friction
                             oracle, a wrapper around a PF or UKF */
} br_app_est_kind_t;

/* Why the outputs are off (br_app_t.fault). Every cause but NONE is latched:
 * each br_app_step then writes duty 0 and returns BR_E_FAULT until br_app_arm. */
typedef enum {
    BR_APP_FAULT_NONE = 0,       /* armed, running */
    BR_APP_FAULT_DISARMED = 1,   /* after init, before the first br_app_arm */
    BR_APP_FAULT_CTRL_INPUT = 2, /* br_ctrl_step BR_E_INPUT: reference or compensation bad */
    BR_APP_FAULT_CTRL_STATE = 3, /* br_ctrl_step BR_E_NUMERIC (or another error): integrator or law */
    BR_APP_FAULT_ESTIMATOR = 4,  /* the estimator's step or predict failed */
    BR_APP_FAULT_ENC_JUMP = 5,   /* |counts delta| above the axis's maximum speed */
    BR_APP_FAULT_ENC_STALE = 6,  /* more failed encoder reads in a row than enc_stale_periods */
    BR_APP_FAULT_ENC_FROZEN = 7, /* counter unchanged where the model predicts more than
                                    stuck_counts of motion (br_app_motion_cfg_t) */
    BR_APP_FAULT_DEADLINE = 8,   /* missed control periods (reported by the caller, br_app_fault) */
    BR_APP_FAULT_HAL = 9,        /* pwm_write failed */
    BR_APP_FAULT_LOST_LOCK = 10, /* more than lock_max_outliers outlier steps (BR_W_OUTLIER: the
                                    estimator rejected the measurement, re-anchoring included)
                                    within the last lock_window_periods periods */
    BR_APP_FAULT_SPEED = 11,     /* measured |speed| above speed_fault_mps */
    BR_APP_FAULT_FOLLOWING = 12, /* |limited reference - position| above max_following_m */
    BR_APP_FAULT_TRAVEL = 13,    /* position beyond a soft travel limit by more than max_following_m */
    BR_APP_FAULT_REF_UNDERRUN = 14 /* the streamed reference ran dry for longer than its fault
                                      time (br_refq, reported by br_svc through br_app_fault) */
} br_app_fault_t;

/* How a latched fault stops the axis (br_app_t.stop, docs/modules/app.md). */
typedef enum {
    BR_APP_STOP_OFF = 0,     /* outputs off (duty 0, pwm_disable): the loop cannot run (HAL,
                                DEADLINE) */
    BR_APP_STOP_BRAKING = 1, /* the position is trusted: the controller follows a ramp to
                                standstill at max_accel_mps2 (no compensation), then outputs off */
    BR_APP_STOP_OPEN = 2     /* the position is not trusted (encoder faults, CTRL_STATE): a
                                braking force against the last trusted speed, (M + J/L^2)
                                max_accel - Fc, for the periods that speed takes to stop at
                                max_accel, then outputs off */
} br_app_stop_t;

/* The guards of one period (docs/reliability.md). br_app_guard_cfg builds them
 * from the machine's maximum speed. */
typedef struct {
    uint32_t enc_max_delta_counts; /* largest |counts delta| the axis can make in one period
                                      (max speed x period), 1..2^30; above: BR_APP_FAULT_ENC_JUMP */
    uint32_t enc_stale_periods;    /* failed reads in a row that are held (last count, the
                                      estimator predicts); the next one faults. 0..1000 */
    uint32_t lock_window_periods;  /* the lock monitor's window: the last so many periods,
                                      1..BR_APP_LOCK_WINDOW_MAX */
    uint32_t lock_max_outliers;    /* outlier steps allowed in the window, 0..window - 1; one
                                      more is BR_APP_FAULT_LOST_LOCK */
} br_app_guard_cfg_t;

/* Largest lock window (the window is a bit per period in br_app_t). */
#define BR_APP_LOCK_WINDOW_MAX 1024u
#define BR_APP_LOCK_WORDS (BR_APP_LOCK_WINDOW_MAX / 32u)

/* Defaults of br_app_guard_cfg (docs/reliability.md). */
#define BR_APP_GUARD_STALE_PERIODS 3u   /* three missed reads are held, the fourth faults */
#define BR_APP_GUARD_LOCK_S 0.1f        /* lock monitor: outlier steps in the last 100 ms ... */
#define BR_APP_GUARD_LOCK_FRACTION 0.25f /* ... above a quarter of its periods: lost lock (docs/reliability.md) */

/* The guards for a period dt_s and a maximum speed in counts/s (the machine's
 * BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F): enc_max_delta_counts =
 * ceil(BR_APP_JUMP_SPEEDS speed dt) (a delta no motion below the speed fault
 * can make, see BR_APP_JUMP_SPEEDS), lock_window_periods =
 * ceil(BR_APP_GUARD_LOCK_S / dt), lock_max_outliers = ceil(BR_APP_GUARD_LOCK_FRACTION
 * window) (25 of 100 periods at 1 ms, 17 of 67 at 1.5 ms), the defaults above. A
 * non-finite or non-positive input gives a configuration br_app_init rejects. */
br_app_guard_cfg_t br_app_guard_cfg(float dt_s, float max_speed_counts_per_s);

/* The speed fault's margin over the machine's max_speed_mps (the reference
 * limiter's speed): a measured speed above max_speed (1 + margin) latches SPEED.
 * 20 %: H-inf overshoots the limiter's corner from max_accel to max_speed by
 * 12.4 % on the reference machine (br_faults, ref_step_10mm; docs/reliability.md);
 * firmware/design/machine.py's SPEED_MARGIN is this value (test_app holds
 * the stop bound it gives equal). */
#define BR_APP_SPEED_MARGIN 0.2f
/* The encoder jump limit in machine speeds: twice the speed fault's speed is
 * more than the axis can reach in one period after the speed fault's limit
 * (its acceleration times a period is far below the speed: 14 mm/s at 1 ms on
 * the reference machine), so a larger delta is a lie of the encoder. */
#define BR_APP_JUMP_SPEEDS (2.0f * (1.0f + BR_APP_SPEED_MARGIN))
/* The stuck-encoder detector's threshold: predicted motion, in counts, that a
 * still counter must not hide. */
#define BR_APP_STUCK_COUNTS 8.0f
/* The stuck-encoder model's allowance for the count's quantization, counts per
 * period^2: the speed change F_hold is taken from is the difference of two
 * one-period count differences, each within one count of the motion, so it
 * is off by less than 2 (F_hold by less than 2 mass / (counts_per_m dt^2):
 * 0.5 N on the reference machine, 280 N on an axis of 0.1 um counts at
 * 0.27 ms; docs/reliability.md, "Stuck encoder and quantization"). */
#define BR_APP_STUCK_QUANT_ACCEL 2.0f
/* Standstill after a braking ramp: so many periods at zero reference speed,
 * then outputs off. */
#define BR_APP_BRAKE_SETTLE_PERIODS 20u

/* The machine's values the drive protections derive from, physical units
 * (bristle/br_machine_cfg.h: BR_MACHINE_APP_MACHINE, from the machine file). */
typedef struct {
    float lead_mprad;       /* L, m/rad */
    float rad_per_count;    /* encoder resolution on the motor */
    float mass_kg;          /* table mass M */
    float inertia_kgm2;     /* motor + screw J */
    float Fc_N;             /* Coulomb friction: the least force that brakes a coasting axis */
    float Fs_N;             /* stiction: the most force friction holds at standstill */
    float max_speed_mps;    /* limits.max_speed_mps */
    float max_accel_mps2;   /* limits.max_accel_mps2 */
    float max_following_m;  /* limits.max_following_error_m */
    float travel_m;         /* limits.travel_m: the stroke ... */
    float travel_min_m;     /* ... from here (limits.travel_min_m; position 0 is count 0) */
    float period_s;         /* control.period_s: a fault is seen a period late */
    int coast_in_stroke;    /* limits.coast_stop: 1 stroke (the limiter keeps a coast with the
                               outputs off inside the stroke), 0 external (no cap) */
    float delay_s;          /* causes.actuator_delay.delay_s (0: none): a command's force reaches
                               the axis so late */
} br_app_machine_t;

/* The drive protections of br_app_step, derived by br_app_motion_cfg
 * (docs/modules/app.md, "Drive protections"). */
typedef struct {
    float counts_per_m;      /* 1 / (L rad_per_count) */
    float max_speed_mps;     /* the reference limiter's speed */
    float max_accel_mps2;    /* the reference limiter's and the braking ramp's acceleration */
    float speed_fault_mps;   /* max_speed (1 + BR_APP_SPEED_MARGIN): above, SPEED */
    float max_following_m;   /* |limited reference - position| above: FOLLOWING */
    float soft_min_m;        /* soft travel limits: the reference is held inside them, a */
    float soft_max_m;        /* position beyond them by max_following_m is TRAVEL */
    float stop_bound_m;      /* the stopping distance bound the soft limits keep from the ends */
    float coast_decel_mps2;  /* the coast envelope's deceleration, Fc / mass; 0: no envelope
                                (limits.coast_stop external) */
    float brake_N;           /* the open-loop braking force: mass max_accel - Fc, >= 0 */
    float mass_kg;           /* moved mass M + J / L^2 (the stuck-encoder model) */
    float stuck_band_N;      /* force change friction can hold without motion: 2 Fs */
    float stuck_counts;      /* predicted motion without a count that latches ENC_FROZEN */
    float delay_s;           /* the actuator delay the stuck-encoder model's force comes after:
                                >= 0, within br_est_delay_fits at the controller's period */
} br_app_motion_cfg_t;

/* The protections of machine m (docs/modules/app.md): speed_fault = max_speed
 * (1 + BR_APP_SPEED_MARGIN); stop_bound = speed_fault^2 / (2 max_accel) (a
 * braking ramp, closed or open loop, from the speed fault's speed) +
 * speed_fault period (the period the fault is seen in) + max_following;
 * soft limits = [travel_min + stop_bound, travel_min + travel - stop_bound];
 * brake_N = max(0, mass max_accel - Fc); mass =
 * M + J / L^2; stuck band 2 Fs; BR_APP_STUCK_COUNTS; delay_s as m's; coast_decel = Fc / mass
 * with coast_in_stroke, else 0 (the coast envelope, br_app_ref_limit). Values br_app_init
 * rejects (all zero) for a NULL m or a non-finite or non-positive value. */
br_app_motion_cfg_t br_app_motion_cfg(const br_app_machine_t *m);
/* Can be const, in flash. Only the pointer the kind names is read. */
typedef struct {
    const br_ctrl_cfg_t *ctrl;
    br_app_est_kind_t est;
    const br_pf_cfg_t *pf;
    const br_ukf_cfg_t *ukf;
    const br_est_t *ext;
    br_app_guard_cfg_t guard;
    br_app_motion_cfg_t motion;
} br_app_cfg_t;

/* The estimator's state, owned by the caller (see above); only the pointer
 * the configuration's kind names is used, the others may be NULL. */
typedef struct {
    br_pf_t *pf;
    br_ukf_t *ukf;
} br_app_mem_t;

typedef struct {
    const br_hal_t *hal;
    br_est_t est;           /* the estimator the configuration's kind named (step, predict,
                               reset); est.step == NULL: none, H-infinity only */
    br_ctrl_t ctrl;
    float F_hat_N;          /* the period's output: the compensation used (N, load side) */
    br_ctrl_out_t last;     /* the period's output: torque, duty, errors, saturation */
    int ready;              /* br_app_init succeeded */
    br_app_guard_cfg_t guard;
    br_app_fault_t fault;   /* NONE while armed; the latched cause otherwise */
    int32_t last_counts;    /* last good encoder read */
    int have_counts;        /* last_counts valid (a good read since the arm) */
    uint32_t n_stale;       /* failed reads in a row */
    br_app_motion_cfg_t motion;
    br_app_stop_t stop;     /* how the latched fault stops the axis */
    /* the reference limiter (counts, counts per period) */
    int32_t lim_counts;     /* the limited reference: integer part ... */
    float lim_frac;         /* ... and fraction in [0, 1) */
    float lim_v;            /* its speed, counts per period */
    int lim_primed;         /* lim_* valid (the first period after the arm sets them) */
    int lim_active;         /* limiting (the reference was beyond a limit and is not caught up) */
    int ref_limited;        /* the period's flag: the reference handed to the controller was limited */
    uint32_t n_ref_limited; /* periods limited since the arm */
    float lim_vmax, lim_amax; /* the limits in counts per period (per period^2) */
    float lim_lo, lim_hi;   /* the soft travel limits in counts */
    float lim_acoast;       /* the coast envelope's deceleration, counts per period^2 (0: off) */
    float lim_end_lo, lim_end_hi; /* the stroke's ends less the following limit, counts: a coast
                                     from the limited reference stops inside them */
    float mot_k_m;          /* the stuck-encoder model's force per count/period^2: mass / (counts_per_m dt^2) */
    /* measured motion (stuck-encoder model, speed fault) */
    float v_meas;           /* speed of the last good read, counts per period */
    float hold_N;           /* friction + load when the count last moved (model: F - m a) */
    float v_pred;           /* the model's speed since the count stopped, counts per period */
    float d_pred;           /* the model's motion since the count stopped, counts */
    br_est_delay_t mot_delay; /* the commands over the actuator delay (motion.delay_s) */
    float mot_F_N;          /* the force that reached the axis over the period that ended (load side) */
    /* the braking ramp */
    int32_t brk_counts;     /* the ramp's position: integer part ... */
    float brk_frac;         /* ... and fraction */
    float brk_v;            /* its speed, counts per period */
    float brk_duty;         /* BR_APP_STOP_OPEN: the braking duty */
    uint32_t brk_left;      /* periods left before outputs off */
    uint32_t lock_bits[BR_APP_LOCK_WORDS]; /* lock monitor: bit k = period k of the window was an outlier */
    uint32_t lock_pos;      /* the window's slot of the next period */
    uint32_t n_lock;        /* outlier periods in the window (the bits set) */
} br_app_t;

/* The estimator the configuration names, initialised in its storage, as the
 * br_est_t the loop drives: br_pf_est / br_ukf_est (step, predict, reset),
 * the caller's *cfg->ext for EXTERN, est->step == NULL for BR_APP_EST_NONE.
 * The one place where the kind is read: the period and the arm go through
 * the interface. For a caller that puts something in front of it (the
 * simulator's extended-model wrapper) before handing it to br_app_init as
 * BR_APP_EST_EXTERN.
 * BR_E_NULL: cfg, cfg->ctrl, est, or the config / storage / br_est_t the kind
 * needs is NULL (mem may be NULL for NONE and EXTERN). BR_E_PARAM: an unknown
 * kind, or a PF / UKF whose period (model.dt_s) is not the controller's
 * (equal to 1e-6 relative); else the filter's own init status. */
br_status_t br_app_est_init(const br_app_cfg_t *cfg, const br_app_mem_t *mem, br_est_t *est);

/* Validates and initialises: the estimator (br_app_est_init), the guards
 * (BR_E_PARAM), the HAL (BR_E_NULL: hal, its encoder_read, pwm_write or
 * tick_wait NULL), then the controller (br_ctrl_init's status). On any error
 * app is left not ready (br_app_step then returns BR_E_STATE). On success the application is DISARMED: outputs off (duty 0,
 * hal.pwm_disable) until br_app_arm. */
br_status_t br_app_init(br_app_t *app, const br_app_cfg_t *cfg, const br_hal_t *hal, const br_app_mem_t *mem);

/* Arms (after init) or re-arms (after a fault): the controller restarts (its
 * integral and its previous count cleared), the estimator restarts through
 * its reset (br_est_restart: the PF / UKF re-initialised from their own
 * configuration, primed again at the next measurement; an EXTERN estimator
 * without a reset is the caller's), the encoder guards restart, the fault
 * is cleared and hal.pwm_enable (if any) turns the outputs on at duty 0.
 * BR_E_NULL, BR_E_STATE (not initialised), or the re-initialisation's error
 * (the application then stays latched). */
br_status_t br_app_arm(br_app_t *app);

/* Latches a fault from outside the period (BR_APP_FAULT_DEADLINE from the
 * port's missed ticks, a supervisor): duty 0, outputs off. BR_E_FAULT, or
 * BR_E_NULL / BR_E_STATE / BR_E_PARAM (cause NONE or unknown). */
br_status_t br_app_fault(br_app_t *app, br_app_fault_t cause);

/* One control period, after the tick (docs/modules/app.md):
 *   encoder read    a failed read holds the last count moved on at the
 *                   speed measured then (the estimator's predict: the PF /
 *                   UKF predict only; an estimator without one, an EXTERN
 *                   one, holds its estimate) for up to enc_stale_periods
 *                   periods, then ENC_STALE; a delta above
 *                   enc_max_delta_counts is ENC_JUMP; a still count where
 *                   the model predicts motion is ENC_FROZEN, a speed above
 *                   the speed fault's SPEED (br_app_motion_cfg_t);
 *   limits          the reference limited to the machine's speed,
 *                   acceleration and soft travel limits; FOLLOWING, TRAVEL;
 *   estimator       an error is ESTIMATOR (BR_W_OUTLIER: control goes on);
 *   lock monitor    more than lock_max_outliers BR_W_OUTLIER steps within the
 *                   last lock_window_periods periods is LOST_LOCK (a filter
 *                   that keeps re-anchoring has lost the axis: the estimate it
 *                   compensates with is not the axis's friction);
 *   controller      BR_E_INPUT is CTRL_INPUT, any other error CTRL_STATE;
 *   pwm_write       an error is HAL.
 * BR_OK or BR_W_OUTLIER; BR_E_FAULT when a fault latched in this period or
 * was latched before (duty 0 written, outputs disabled; cause in app->fault);
 * BR_E_NULL, BR_E_STATE (not initialised). */
br_status_t br_app_step(br_app_t *app, const br_ref_t *ref);

/* The largest reference speed (m/s) the drive's reference limiter passes
 * untouched at load position pos_m moving toward the high end (toward_hi
 * nonzero) or the low end: max_speed_mps, the braking curve that stops at the
 * soft limit and the coast envelope, at the application's period: the caps
 * br_app_step's limiter applies (docs/modules/app.md, "Drive protections");
 * 0 at or beyond a soft limit, and for an application not initialised or a
 * non-finite position. A tool's question (what a trajectory may ask of this
 * drive), not a control-loop call. */
float br_app_ref_speed_cap_mps(const br_app_t *app, float pos_m, int toward_hi);

#endif
