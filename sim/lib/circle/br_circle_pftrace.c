/* SPDX-License-Identifier: Apache-2.0 */
/* The estimators' state on the circle (br_circle_pftrace.h). */
#include "br_circle_pftrace.h"

#include <math.h>
#include <stdlib.h>

void br_pftrace_headers(const br_pftrace_t *tr)
{
    if (tr->trace)
        fprintf(tr->trace, "label,t_s,axis,v_mps,f_true_N,g_true_N,F_hat_N,th_err_counts,th_sd_counts,best_miss_counts,"
                           "nearest_counts,gate_counts,v_mean_mps,v_sd_mps,z_mean_m,z_sd_m,gp_mean_N,gp_sd_N,ess,nis_avg,q_scale,"
                           "outliers_in_row\n");
    if (tr->posterior)
        fprintf(tr->posterior, "label,t_s,axis,kind,j,th_err_counts,v_mps,z_m,gp_N,f_N\n");
}

/* the plant's Stribeck level at v (eq. 5, delta = 1 as the estimators' model) */
static double g_of(const br_plant_cfg_t *p, double v)
{
    return p->Fc_N + (p->Fs_N - p->Fc_N) * exp(-fabs(v) / p->vs_mps);
}

/* the plant's angle relative to the filter's origin, rad */
static double theta_rel(const br_circle_sample_t *s, int a, double L, int32_t origin, double rpc)
{
    return s->pos_m[a] / L - (double)origin * rpc;
}

void br_pftrace_cloud(const br_pf_t *pf, double mean[BR_NX], double sd[BR_NX], double *miss_counts)
{
    const uint32_t m = pf->cfg.n_particles;
    const double rpc = (double)pf->cfg.est.rad_per_count;
    double sum[BR_NX] = {0}, sum2[BR_NX] = {0};
    for (uint32_t j = 0; j < m; j++)
        for (int i = 0; i < BR_NX; i++) {
            const double v = (double)pf->x[i][j];
            sum[i] += v;
            sum2[i] += v * v;
        }
    for (int i = 0; i < BR_NX; i++) {
        mean[i] = sum[i] / m;
        sd[i] = sqrt(fmax(sum2[i] / m - mean[i] * mean[i], 0.0));
    }
    uint32_t jb = 0;
    for (uint32_t j = 1; j < m; j++)
        if (pf->l[j] > pf->l[jb]) jb = j;
    *miss_counts = NAN;
    for (uint32_t i = 0; i < m; i++)
        if (pf->idx[i] == jb) {
            *miss_counts = ((double)pf->x[BR_X_THETA][i] - (double)pf->prev_frac * rpc) / rpc;
            break;
        }
}

static void trace_row(const br_pftrace_t *tr, const br_circle_sample_t *s, int a)
{
    const br_pf_t *pf = s->pf[a];
    const double rpc = (double)pf->cfg.est.rad_per_count, L = (double)pf->cfg.est.model.lead_mprad;
    double mean[BR_NX], sd[BR_NX], miss;
    br_pftrace_cloud(pf, mean, sd, &miss);
    br_pf_stats_t st;
    const double ess = br_pf_stats(pf, &st) == BR_OK ? (double)st.ess : NAN;
    const double inv2r = (double)pf->inv_2r;
    const double th = theta_rel(s, a, L, pf->origin_counts, rpc);
    fprintf(tr->trace, "%ld,%.6f,%d,%.6e,%.6e,%.4f,%.6e,%.4f,%.4f,%.4f,%.4f,%.4f,%.6e,%.6e,%.6e,%.6e,%.4f,%.4f,%.1f,%.4f,%.4f,%u\n",
            tr->label, s->t_s, a, s->vel_mps[a], s->fnl_N[a], g_of(tr->plant, s->vel_mps[a]), s->F_hat_N[a],
            (th - mean[BR_X_THETA]) / rpc, sd[BR_X_THETA] / rpc, miss, sqrt(-(double)pf->lmax / inv2r) / rpc,
            sqrt(-(double)pf->outlier_l / inv2r) / rpc, L * mean[BR_X_OMEGA], L * sd[BR_X_OMEGA], mean[BR_X_Z],
            sd[BR_X_Z], mean[BR_X_GP], sd[BR_X_GP], ess, (double)pf->nis_avg, (double)pf->q_scale_std,
            (unsigned)pf->n_outliers);
}

/* the posterior of axis a at s->t_s: the truth, then the PF's particles or the UKF's mean and sigma */
static void posterior_rows(const br_pftrace_t *tr, const br_circle_sample_t *s, int a)
{
    FILE *f = tr->posterior;
    fprintf(f, "%ld,%.6f,%d,truth,0,0,%.6e,,%.4f,%.6e\n", tr->label, s->t_s, a, s->vel_mps[a],
            g_of(tr->plant, s->vel_mps[a]), s->fnl_N[a]);
    if (s->pf[a]) {
        const br_pf_t *pf = s->pf[a];
        const double rpc = (double)pf->cfg.est.rad_per_count, L = (double)pf->cfg.est.model.lead_mprad;
        const double th = theta_rel(s, a, L, pf->origin_counts, rpc);
        for (uint32_t j = 0; j < pf->cfg.n_particles; j++)
            /* f_nl stays at its predicted index: particle j's is fnl[idx[j]] */
            fprintf(f, "%ld,%.6f,%d,pf,%u,%.4f,%.6e,%.6e,%.4f,%.6e\n", tr->label, s->t_s, a, (unsigned)j,
                    (th - (double)pf->x[BR_X_THETA][j]) / rpc, L * (double)pf->x[BR_X_OMEGA][j],
                    (double)pf->x[BR_X_Z][j], (double)pf->x[BR_X_GP][j], (double)pf->fnl[pf->idx[j]]);
    }
    if (s->ukf[a]) {
        const br_ukf_t *u = s->ukf[a];
        const double rpc = (double)u->cfg.est.rad_per_count, L = (double)u->cfg.est.model.lead_mprad;
        const double th = theta_rel(s, a, L, u->origin_counts, rpc);
        double sd[BR_NX];
        for (int i = 0; i < BR_NX; i++) sd[i] = sqrt(fmax((double)u->P[i][i], 0.0));
        fprintf(f, "%ld,%.6f,%d,ukf_mean,0,%.4f,%.6e,%.6e,%.4f,%.6e\n", tr->label, s->t_s, a,
                (th - (double)u->x[BR_X_THETA]) / rpc, L * (double)u->x[BR_X_OMEGA], (double)u->x[BR_X_Z],
                (double)u->x[BR_X_GP], s->F_hat_N[a]);
        fprintf(f, "%ld,%.6f,%d,ukf_sd,0,%.4f,%.6e,%.6e,%.4f,\n", tr->label, s->t_s, a, sd[BR_X_THETA] / rpc,
                L * sd[BR_X_OMEGA], sd[BR_X_Z], sd[BR_X_GP]);
    }
}

void br_pftrace_sink(void *user, const br_circle_sample_t *s)
{
    br_pftrace_t *tr = user;
    if (tr->trace)
        for (int a = 0; a < 2; a++)
            if (s->pf[a]) trace_row(tr, s, a);
    if (tr->posterior)
        while (tr->next_at < tr->n_at && s->t_s >= tr->at_s[tr->next_at] - 1e-9) {
            posterior_rows(tr, s, tr->axis);
            tr->next_at++;
        }
}

int br_pftrace_parse_at(const char *tool, const char *val, br_pftrace_t *tr)
{
    const char *p = val;
    int n = 0;
    while (*p) {
        char *end;
        const double t = strtod(p, &end);
        if (end == p || n == BR_PFTRACE_MAX_AT || !(t >= 0.0 && t <= 1e4) || (n > 0 && !(t > tr->at_s[n - 1])) ||
            (*end != ',' && *end != '\0') || (*end == ',' && end[1] == '\0')) {
            fprintf(stderr, "%s: %s: at most %d ascending times in [0, 1e4] s, comma-separated\n", tool, val,
                    BR_PFTRACE_MAX_AT);
            return -1;
        }
        tr->at_s[n++] = t;
        p = *end ? end + 1 : end;
    }
    if (n == 0) {
        fprintf(stderr, "%s: %s: no time given\n", tool, val);
        return -1;
    }
    tr->n_at = n;
    tr->next_at = 0;
    return 0;
}
