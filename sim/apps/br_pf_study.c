/* One H-inf + PF circle run with a given filter setting, for the studies in
 * sim/studies/ (noise-table length and indexing, later Q/R and dt).
 *
 * Usage: br_pf_study [--table FILE] [--skip N] [--particles M] [--dt S]
 *                    [--q QTH,QW,QZ,QG] [--r R] [--duration S]
 *   --table  raw little-endian float32 standard-normal samples (length 2^k);
 *            default: the committed ROM table
 *   --q      process noise variances: theta in counts^2, omega (rad/s)^2,
 *            z m^2, g_p N^2; --r measurement variance in counts^2
 * Prints one JSON object: contour_rms_m, max_err_m, fhat_rms_err_N, outliers. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "circle/br_circle.h"

static float *load_table(const char *path, uint32_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "br_pf_study: cannot open %s\n", path);
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    long bytes = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint32_t n = (uint32_t)(bytes / (long)sizeof(float));
    float *t = malloc((size_t)n * sizeof *t);
    if (!t || n < 2 || (n & (n - 1)) || fread(t, sizeof *t, n, f) != n) {
        fprintf(stderr, "br_pf_study: %s: need 2^k float32 samples (%ld bytes read)\n", path, bytes);
        free(t);
        fclose(f);
        return NULL;
    }
    fclose(f);
    *len = n;
    return t;
}

int main(int argc, char **argv)
{
    br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_PF);
    const float rpc = c.pf.est.rad_per_count;
    float *table = NULL;
    for (int i = 1; i < argc; i++) {
        const char *v = (i + 1 < argc) ? argv[i + 1] : NULL;
        int ok = v != NULL;
        if (ok && strcmp(argv[i], "--table") == 0) {
            table = load_table(v, &c.pf.noise_len);
            ok = table != NULL;
            c.pf.noise = table;
        } else if (ok && strcmp(argv[i], "--skip") == 0) {
            ok = sscanf(v, "%u", &c.pf.noise_skip) == 1;
        } else if (ok && strcmp(argv[i], "--particles") == 0) {
            ok = sscanf(v, "%u", &c.pf.n_particles) == 1;
        } else if (ok && strcmp(argv[i], "--dt") == 0) {
            ok = sscanf(v, "%lf", &c.dt_s) == 1;
            c.pf.est.model.dt_s = (float)c.dt_s;
        } else if (ok && strcmp(argv[i], "--duration") == 0) {
            ok = sscanf(v, "%lf", &c.duration_s) == 1;
        } else if (ok && strcmp(argv[i], "--q") == 0) {
            float *q = c.pf.est.q_var;
            ok = sscanf(v, "%f,%f,%f,%f", &q[0], &q[1], &q[2], &q[3]) == 4;
            q[0] *= rpc * rpc;
        } else if (ok && strcmp(argv[i], "--r") == 0) {
            ok = sscanf(v, "%f", &c.pf.est.r_var_rad2) == 1;
            c.pf.est.r_var_rad2 *= rpc * rpc;
        } else {
            ok = 0;
        }
        if (!ok) {
            fprintf(stderr, "br_pf_study: bad or unknown option %s (see the source's header)\n", argv[i]);
            free(table);
            return 2;
        }
        i++;
    }
    br_circle_result_t r;
    int rc = br_circle_run(&c, NULL, NULL, &r);
    free(table);
    if (rc != 0) return 1;
    printf("{\"contour_rms_m\": %.6e, \"max_err_m\": %.6e, \"fhat_rms_err_N\": %.6e, \"outliers\": %d}\n",
           r.contour_rms_m, r.max_err_m, r.fhat_rms_err_N, r.outlier_steps);
    return 0;
}
