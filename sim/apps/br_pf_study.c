/* SPDX-License-Identifier: Apache-2.0 */
/* One H-inf + PF circle run with a given filter setting, for the studies in
 * sim/studies/ (noise-table length and indexing, later Q/R and dt).
 *
 * Usage: br_pf_study [--table FILE] [--skip N] [--particles M] [--dt S]
 *                    [--q QTH,QW,QZ,QG] [--r R] [--duration S]
 *   --table  raw little-endian float32 standard-normal samples (length 2^k);
 *            default: the committed ROM table
 *   --q      process noise variances: theta in counts^2, omega (rad/s)^2,
 *            z m^2, g_p N^2; --r measurement variance in counts^2
 * Prints one JSON object: contour_rms_m, max_err_m, fhat_rms_err_N, outliers
 * (exit 1 when one is not finite). Bounds: br_tool_limits.h. */
#define _POSIX_C_SOURCE 200809L /* stat */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "circle/br_circle.h"
#include "tool/br_args.h"
#include "tool/br_tool_limits.h"

#define TOOL "br_pf_study"

static float *load_table(const char *path, uint32_t *len)
{
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) { /* a FIFO's open would wait for a writer */
        fprintf(stderr, "%s: %s: not a regular file (a device, a FIFO or a folder)\n", TOOL, path);
        return NULL;
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "%s: cannot open %s\n", TOOL, path);
        return NULL;
    }
    long bytes = -1;
    if (fseek(f, 0, SEEK_END) == 0) bytes = ftell(f);
    const long n = bytes / (long)sizeof(float);
    float *t = NULL;
    if (bytes < 0 || n < 2 || n > BR_TOOL_TABLE_MAX_SAMPLES || (n & (n - 1)) || bytes % (long)sizeof(float) ||
        fseek(f, 0, SEEK_SET) != 0 || !(t = malloc((size_t)n * sizeof *t)) || fread(t, sizeof *t, (size_t)n, f) != (size_t)n) {
        fprintf(stderr, "%s: %s: need 2^k float32 samples, 2 .. %ld (%ld bytes)\n", TOOL, path,
                BR_TOOL_TABLE_MAX_SAMPLES, bytes);
        free(t);
        fclose(f);
        return NULL;
    }
    fclose(f);
    for (long i = 0; i < n; i++) {
        if (!isfinite(t[i])) {
            fprintf(stderr, "%s: %s: sample %ld is not finite\n", TOOL, path, i);
            free(t);
            return NULL;
        }
    }
    *len = (uint32_t)n;
    return t;
}

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s [--table FILE] [--skip N] [--particles M] [--dt S] [--q QTH,QW,QZ,QG] [--r R] [--duration S]\n"
            BR_ARGS_COMMON_USAGE
            "  --table FILE        raw little-endian float32 standard-normal samples (2^k); default the ROM table\n"
            "  --skip N            table samples skipped per draw\n"
            "  --particles M       number of particles\n"
            "  --dt S              control period\n"
            "  --q QTH,QW,QZ,QG    process noise: theta counts^2, omega (rad/s)^2, z m^2, g_p N^2\n"
            "  --r R               measurement variance, counts^2 (> 0)\n"
            "  --duration S        length of the circle run\n"
            "bounds: --particles 1 .. %u, --dt %g .. %g s, --duration %g .. %g s (docs/tools.md)\n",
            argv0, argv0, BR_TOOL_PARTICLES_MAX, BR_TOOL_DT_MIN_S, BR_TOOL_DT_MAX_S, BR_TOOL_DURATION_MIN_S,
            BR_TOOL_DURATION_MAX_S);
    return 2;
}

/* n comma-separated finite numbers >= 0 (variances) */
static int parse_variances(const char *val, float *q, int n)
{
    const char *p = val;
    for (int k = 0; k < n; k++) {
        char *end = NULL;
        const float v = strtof(p, &end);
        if (end == p || !isfinite(v) || v < 0.0f || *end != (k + 1 < n ? ',' : '\0')) return -1;
        q[k] = v;
        p = end + 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_PF);
    const float rpc = c.pf.est.rad_per_count;
    const char *table_path = NULL;
    static const struct option opts[] = {{"table", required_argument, NULL, 't'},
                                         {"skip", required_argument, NULL, 's'},
                                         {"particles", required_argument, NULL, 'p'},
                                         {"dt", required_argument, NULL, 'd'},
                                         {"duration", required_argument, NULL, 'D'},
                                         {"q", required_argument, NULL, 'q'},
                                         {"r", required_argument, NULL, 'r'},
                                         {NULL, 0, NULL, 0}};
    br_args_t p;
    if (br_args_start(&p, TOOL, argc, argv, usage)) return 0;
    const char *v;
    for (int o; (o = br_args_next(&p, opts, &v)) != BR_ARGS_END;) {
        long n = 0;
        int bad = 0;
        switch (o) {
        case 't': table_path = v; break;
        case 's':
            bad = br_arg_long(TOOL, p.opt, v, 0, BR_TOOL_TABLE_MAX_SAMPLES, &n);
            c.pf.noise_skip = (uint32_t)n;
            break;
        case 'p':
            bad = br_arg_long(TOOL, p.opt, v, 1, BR_TOOL_PARTICLES_MAX, &n);
            c.pf.n_particles = (uint32_t)n;
            break;
        case 'd':
            bad = br_arg_double(TOOL, p.opt, v, BR_TOOL_DT_MIN_S, BR_TOOL_DT_MAX_S, &c.dt_s);
            c.pf.est.model.dt_s = (float)c.dt_s;
            break;
        case 'D': bad = br_arg_double(TOOL, p.opt, v, BR_TOOL_DURATION_MIN_S, BR_TOOL_DURATION_MAX_S, &c.duration_s); break;
        case 'q': {
            float *q = c.pf.est.q_var;
            bad = parse_variances(v, q, 4);
            q[0] *= rpc * rpc;
            if (bad) fprintf(stderr, "%s: --q %s: four comma-separated numbers >= 0\n", TOOL, v);
            break;
        }
        case 'r':
            bad = parse_variances(v, &c.pf.est.r_var_rad2, 1) || c.pf.est.r_var_rad2 <= 0.0f;
            c.pf.est.r_var_rad2 *= rpc * rpc;
            if (bad) fprintf(stderr, "%s: --r %s: a number > 0\n", TOOL, v);
            break;
        default: bad = 1; break; /* BR_ARGS_BAD: reported */
        }
        if (bad) return usage(argv[0], stderr);
    }
    float *table = NULL;
    if (table_path) {
        table = load_table(table_path, &c.pf.noise_len);
        if (!table) return 1;
        c.pf.noise = table;
    }
    br_circle_result_t r;
    int rc = br_circle_run(&c, NULL, NULL, &r);
    free(table);
    if (rc != 0) return 1;
    if (!isfinite(r.contour_rms_m) || !isfinite(r.max_err_m) || !isfinite(r.fhat_rms_err_N)) {
        fprintf(stderr, "%s: the run gave a non-finite result\n", TOOL);
        return 1;
    }
    printf("{\"contour_rms_m\": %.6e, \"max_err_m\": %.6e, \"fhat_rms_err_N\": %.6e, \"outliers\": %d}\n",
           r.contour_rms_m, r.max_err_m, r.fhat_rms_err_N, r.outlier_steps);
    return 0;
}
