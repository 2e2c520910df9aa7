/* SPDX-License-Identifier: Apache-2.0 */
/* br_circle_ext: the gain of a diagnosis in control terms. The thesis circle
 * on the reference machine with causes switched on (the "hidden" ones), with
 * H-inf only, with H-inf + the plant's own force (an oracle), with H-inf + an
 * estimator on the nominal model (the firmware's as configured), and with H-inf + the same estimator on the extended model a
 * diagnosis saved (model.json): the firmware's own extended model, its
 * br_model_cfg_t.causes set from the model's. docs/diagnose.md.
 *
 * Usage: br_circle_ext [--model MODEL.json] [--est ukf|pf] [--ahead P] [--json OUT] [cause options]
 *                      [--radius-m R] [--feed-mm-min F] [--dir cw|ccw]
 * (the circle: br_circle_args.h, default the thesis's)
 * Prints one line per run and, with --json, writes them (to a temporary file
 * renamed at the end, br_outfile.h: a failed run writes nothing). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "circle/br_circle.h"
#include "circle_args/br_circle_args.h"
#include "plant/br_model_params.h"
#include "plant/br_plant_json.h"
#include "cause_args/br_cause_args.h"
#include "tool/br_args.h"
#include "tool/br_outfile.h"
#include "tool/br_run_report.h"

#define TOOL "br_circle_ext"

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s [--model MODEL.json] [--est ukf|pf] [--ahead P] [--json OUT] [cause options]\n"
            "       [--radius-m R] [--feed-mm-min F] [--dir cw|ccw]\n" BR_ARGS_COMMON_USAGE
            "  --model MODEL.json  a diagnosis's saved model: adds the extended-model run\n"
            "  --est ukf|pf        the estimator beside H-inf (default ukf)\n"
            "  --ahead P           the estimator's compensation lead, periods beyond the delay\n"
            "                      (est.comp_ahead_periods; default the machine file's)\n"
            "  --json OUT          write the runs' figures to OUT as well\n"
            BR_CIRCLE_USAGE("--dir cw|ccw       "),
            argv0, argv0);
    br_cause_usage(to, "");
    return 2;
}

int main(int argc, char **argv)
{
    const char *model = NULL, *json = NULL, *est = "ukf";
    double ahead = -1.0; /* < 0: the machine file's */
    br_plant_cfg_t plant = br_plant_cfg_reference();
    br_circle_path_t path = BR_CIRCLE_PATH_DEFAULT;
    static const struct option opts[] = {{"model", required_argument, NULL, 'm'},
                                         {"json", required_argument, NULL, 'j'},
                                         {"est", required_argument, NULL, 'e'},
                                         {"ahead", required_argument, NULL, 'a'},
                                         BR_CAUSE_LONGOPTS BR_CIRCLE_LONGOPTS BR_CIRCLE_LONGOPT_DIR{NULL, 0, NULL, 0}};
    br_args_t p;
    if (br_args_start(&p, TOOL, argc, argv, usage)) return 0;
    const char *val;
    for (int c; (c = br_args_next(&p, opts, &val)) != BR_ARGS_END;) {
        if (c == BR_CAUSE_OPT) {
            if (br_cause_arg(p.opt, val, &plant) < 0) return 2;
        } else if (c == BR_CIRCLE_OPT) {
            if (br_circle_arg(TOOL, p.opt, val, 0, &path) != 0) return usage(argv[0], stderr);
        } else if (c == 'm') model = val;
        else if (c == 'j') json = val;
        else if (c == 'a') {
            if (br_arg_double(TOOL, "--ahead", val, 0.0, (double)BR_EST_AHEAD_MAX_PERIODS, &ahead) != 0) return 2;
        }
        else if (c == 'e' && (strcmp(val, "ukf") == 0 || strcmp(val, "pf") == 0)) est = val;
        else {
            if (c == 'e') fprintf(stderr, "%s: --est %s: must be ukf or pf\n", TOOL, val);
            return usage(argv[0], stderr);
        }
    }
    {
        const br_circle_cfg_t thesis = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
        if (br_circle_path_check(TOOL, &path, &thesis) != 0) return usage(argv[0], stderr);
    }
    const int use_pf = strcmp(est, "pf") == 0;
    br_plant_cfg_t saved;
    char msg[512];
    if (model && br_plant_cfg_from_model_json(model, &plant, &saved, msg, sizeof msg) != 0) {
        fprintf(stderr, "%s: %s\n", TOOL, msg);
        return 1;
    }
    const br_circle_ctrl_t ctrl = use_pf ? BR_CTRL_HINF_PF : BR_CTRL_HINF_UKF;
    struct {
        const char *name;
        br_circle_ctrl_t ctrl;
        int extended;
    } runs[4] = {{"hinf_only", BR_CTRL_HINF_ONLY, 0},
                 {"hinf_true", BR_CTRL_HINF_TRUE, 0}, /* the oracle: the plant's own force (br_plant_comp_force_N) */
                 {"est_nominal", ctrl, 0},
                 {"est_extended", ctrl, 1}};
    br_outfile_t js = {0}; /* a temporary file until every run succeeded (br_outfile.h) */
    if (json) {
        if (br_outfile_open(&js, TOOL, json) != 0) return 1;
        br_circle_cfg_t c0 = br_circle_cfg_thesis(ctrl);
        br_circle_use_ahead(&c0, ahead); /* the lead the runs below take */
        br_circle_use_path(&c0, path.radius_m, path.feed_mps, path.dir == BR_CIRCLE_DIR_CCW);
        const double lead = (double)(use_pf ? c0.pf.est.comp_ahead_periods : c0.ukf.est.comp_ahead_periods);
        fprintf(js.f,
                "{\n  \"generator\": \"br_circle_ext (sim/apps/br_circle_ext.c)\",\n  \"estimator\": \"%s\",\n"
                "  \"comp_ahead_periods\": %.9g",
                est, lead);
        fprintf(js.f, ",\n  \"circle\": {\"radius_m\": %.9g, \"period_s\": %.9g, \"direction\": \"%s\"}", c0.radius_m,
                c0.period_s, c0.dir < 0.0 ? "ccw" : "cw");
    }
    for (int r = 0; r < (model ? 4 : 3); r++) {
        br_circle_cfg_t c = br_circle_cfg_thesis(runs[r].ctrl);
        c.plant = plant;
        br_circle_use_path(&c, path.radius_m, path.feed_mps, path.dir == BR_CIRCLE_DIR_CCW);
        br_circle_use_ahead(&c, ahead); /* every estimator run, nominal and extended, with the same lead */
        if (runs[r].extended) {
            /* the estimator predicts and compensates with the diagnosed causes */
            const br_causes_t causes = br_causes_from_model(&saved);
            br_circle_use_causes(&c, &causes);
        }
        br_circle_result_t res;
        /* 1: the firmware stopped the axis safe (a fault), part of the result */
        const int rc = br_circle_run(&c, NULL, NULL, &res);
        if (rc < 0 || !isfinite(res.contour_rms_m) || !isfinite(res.max_err_m)) {
            fprintf(stderr, "%s: run %s %s; nothing written\n", TOOL, runs[r].name,
                    rc < 0 ? "failed" : "gave a non-finite result");
            br_outfile_discard(&js);
            return 1;
        }
        /* a faulted run is a fault (time, cause), never an RMS beside full runs (br_run_report.h) */
        const br_run_report_t rep = {res.contour_rms_m, res.max_err_m, res.fault_status, res.fault_cause,
                                     res.fault_t_s};
        br_run_print(stdout, runs[r].name, "contour", &rep);
        if (js.f) {
            fprintf(js.f, ",\n  \"%s\": {", runs[r].name);
            br_run_json(js.f, "contour_rms_m", "max_err_m", &rep);
            fprintf(js.f, ", \"outlier_steps\": %d}", res.outlier_steps);
        }
    }
    if (js.f) {
        fprintf(js.f, "\n}\n");
        if (br_outfile_commit(&js, TOOL) != 0) return 1;
    }
    return 0;
}
