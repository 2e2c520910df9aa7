/* SPDX-License-Identifier: Apache-2.0 */
/* The image in the loop's host side (docs/link.md, "The image in the loop",
 * "Tuning on the target"): one QEMU per axis of the circle, each running the
 * production image (target/mps2/pil_main.c) with its link on UART0 and its
 * plant port on UART1 (FIFOs, -serial pipe:), and runs of the circle through
 * them in lockstep with the host plant (br_circle_run_remote).
 *
 * The QEMUs stay up between runs, as a real axis's firmware does: before a
 * run, the parameter writes go on the link while the axis is disarmed (one
 * request per period, the plant at rest), then the setpoints and the arm;
 * after it, the disarm and the fault reset, so that the next run starts from
 * a disarmed axis whatever the last one did. The first run without parameter
 * writes is the one br_pil has always run (bit for bit the simulator's). */
#ifndef BR_PIL_LOOP_H
#define BR_PIL_LOOP_H

#include <stdint.h>
#include <sys/types.h>

#include "bristle/br_link.h"
#include "circle/br_circle.h"

#define BR_PIL_PARAMS_MAX 8

/* one axis's image: its QEMU, the four FIFO ends, the link's and the plant port's state */
typedef struct {
    pid_t pid;
    char dir[512];
    int link_in, link_out, plant_in, plant_out; /* the host's ends: in = to the image */
    uint16_t link_seq, plant_seq;
    uint32_t link_bytes; /* written on the link since the start */
    uint32_t tick;       /* the next period's tick (the image's service counts the same) */
    uint32_t base;       /* the tick of this run's first armed period */
    int32_t last_counts; /* the count sent last (held after a run, the axis disarmed) */
    br_link_dec_t plant_dec, link_dec;
    int fault_cause;     /* from the link's fault report (-1: none seen) */
    uint32_t fault_tick;
    int n_replies;       /* the param_value reports of this run, in order */
    uint16_t reply_id[BR_PIL_PARAMS_MAX];
    float reply_value[BR_PIL_PARAMS_MAX];
    int reply_status[BR_PIL_PARAMS_MAX];
} br_pil_axis_t;

typedef struct {
    uint16_t id;  /* BR_LINK_PARAM_* (bristle_gen/link/br_link_params.h) */
    float value;  /* in the parameter's unit */
} br_pil_param_t;

/* The contour error a user measures on a real axis: the encoder's position
 * (the count's centre, (counts + 0.5) counts, both axes) against the
 * commanded circle, hypot(x, y) - A; its sums over the periods added. */
typedef struct {
    double m_per_count, radius_m, sum2, emax;
    long n;
} br_pil_meas_t;

void br_pil_meas_init(br_pil_meas_t *m, const br_circle_cfg_t *c);
void br_pil_meas_add(br_pil_meas_t *m, int32_t x_counts, int32_t y_counts);
/* its RMS (0 with no period) */
double br_pil_meas_rms(const br_pil_meas_t *m);

typedef struct {
    br_pil_axis_t ax[2];
    int started;      /* axes whose QEMU runs */
    int keep;         /* 1: the work folders are the caller's (kept) */
    double timeout_s; /* for one answer of the image */
    /* the run in progress */
    const br_circle_cfg_t *c;
    long n;                               /* the circle's last period */
    const br_pil_param_t *params;
    int n_params;
    float *duty[2];                       /* the controller's duty per period (NULL: not kept) */
    br_pil_meas_t meas;                   /* the measured contour error */
    int32_t meas_counts[2];               /* the period's counts from the image's samples */
} br_pil_loop_t;

/* A run's outcome. res: br_circle_run_remote's (the plant's truth: what the
 * simulator's tables report). meas_*: what a user has on a real axis,
 * br_pil_meas_t over the image's own samples (the telemetry's counts), the
 * periods run. params_ok: every parameter write was answered with status 0
 * and the value written (R, which the image keeps in rad^2, to a relative
 * 1e-6), on both axes (1; 0: refused or unanswered: no result). */
typedef struct {
    br_circle_result_t res;
    double meas_rms_m, meas_max_m;
    int params_ok;
    double wall_s;
} br_pil_run_t;

/* Starts a QEMU running image with the estimator est (none, ukf, pf) for each
 * axis; work: the folder for the FIFOs and logs (NULL: new ones under /tmp,
 * removed at close). 0, or -1 with a message on stderr. */
int br_pil_loop_open(br_pil_loop_t *L, const char *qemu, const char *image, const char *est, const char *work,
                     double timeout_s);

/* One run of the circle c (its controller the image's estimator) with the
 * parameter writes params[0..n_params) before the arm; duty[i] (n + 1
 * floats, or NULL) gets axis i's duty per period. 0 (the run went to the end
 * or stopped on a fault: out->res.fault_status), or -1 when the image did not
 * answer (message on stderr; the loop is then unusable). */
int br_pil_loop_run(br_pil_loop_t *L, const br_circle_cfg_t *c, const br_pil_param_t *params, int n_params,
                    float *duty[2], br_pil_run_t *out);

/* Stops the QEMUs; the work folders are removed unless they were given. */
void br_pil_loop_close(br_pil_loop_t *L);

/* A stop by signal (docs/link.md, "The image in the loop"). From
 * br_pil_loop_open to br_pil_loop_close, SIGINT, SIGTERM and SIGHUP only
 * record themselves: the run in progress (or the next open or run) ends with
 * -1 and a message, the tool goes its ordinary failure path (close removes the
 * work folders, its temporary outputs are discarded) and ends with
 * br_pil_loop_end. SIGKILL cannot be caught: the QEMUs then end with the tool
 * (PR_SET_PDEATHSIG) and the folders stay. */
/* the signal that asked the stop, 0 when none */
int br_pil_loop_stopped(void);
/* rc when no signal asked the stop; else the signal is raised again with its
 * default action (the exit status of a killed tool) after the caller's
 * clean-up. The last call of a tool's main: return br_pil_loop_end(rc). */
int br_pil_loop_end(int rc);

#endif
