/* SPDX-License-Identifier: Apache-2.0 */
/* The tuner's delayed guard plants (sim/lib/tune_delay/br_tune_delay.h): a setting that
 * stops the axis on one counts as a failure, never as a figure. Every value
 * comes from the machine under test (its generated headers, through
 * br_circle_cfg_thesis), so the test holds on any machine file
 * (tests/machine: machine_heavy runs it on machines/heavy.json). */
#include "br_test.h"

#include "bristle_gen/machine/br_machine.h"
#include "tune_delay/br_tune_delay.h"

static br_tune_delay_t g; /* large: static */

static const br_circle_ctrl_t ests[] = {BR_CTRL_HINF_UKF, BR_CTRL_HINF_PF};

/* the machine's committed (tuned) estimator settings as the tuner hands them
 * over: the delay identification off */
static br_circle_cfg_t as_tuned(br_circle_ctrl_t ctrl)
{
    br_circle_cfg_t c = br_circle_cfg_thesis(ctrl);
    br_circle_use_delay_id(&c, 0);
    return c;
}

static br_est_cfg_t *est_of(br_circle_cfg_t *c, br_circle_ctrl_t ctrl)
{
    return ctrl == BR_CTRL_HINF_UKF ? &c->ukf.est : &c->pf.est;
}

static void assert_dlyid_equal(const br_dlyid_cfg_t *a, const br_dlyid_cfg_t *b)
{
    assert_int_equal(a->n_cand, b->n_cand);
    assert_true(a->step_s == b->step_s && a->q_force_N2ps == b->q_force_N2ps && a->memory_s == b->memory_s &&
                a->warmup_s == b->warmup_s && a->switch_ratio == b->switch_ratio);
}

/* the committed tunings run every delayed plant to the end */
static void test_committed_runs(void **st)
{
    (void)st;
    static const double delay_s[BR_TUNE_DELAY_N] = BR_TUNE_DELAY_S_LIST;
    for (int e = 0; e < 2; e++) {
        br_tune_delay_init(&g, ests[e]);
        for (int k = 0; k < BR_TUNE_DELAY_N; k++) assert_true(g.plant[k].plant.delay_s == delay_s[k]);
        const br_circle_cfg_t c = as_tuned(ests[e]);
        assert_true(br_tune_delay_failed(&g, &c) == 0.0);
    }
}

/* each guard run takes the candidate's settings and turns the machine's delay
 * identification on (on in every machine file), which the tuner leaves off */
static void test_identification_on(void **st)
{
    (void)st;
    for (int e = 0; e < 2; e++) {
        br_tune_delay_init(&g, ests[e]);
        br_circle_cfg_t machine = br_circle_cfg_thesis(ests[e]);
        assert_true(est_of(&machine, ests[e])->delay_id.n_cand > 0u);
        br_circle_cfg_t c = as_tuned(ests[e]);
        assert_int_equal(est_of(&c, ests[e])->delay_id.n_cand, 0u);
        est_of(&c, ests[e])->q_var[1] *= 2.0f; /* a candidate, not the machine's setting */
        for (int k = 0; k < BR_TUNE_DELAY_N; k++) {
            br_circle_cfg_t p = br_tune_delay_run_cfg(&g, &c, k);
            assert_true(p.plant.delay_s == g.plant[k].plant.delay_s);
            assert_true(est_of(&p, ests[e])->q_var[1] == est_of(&c, ests[e])->q_var[1]);
            assert_dlyid_equal(&est_of(&p, ests[e])->delay_id, &est_of(&machine, ests[e])->delay_id);
        }
    }
}

/* a setting that stops the axis on this machine: the estimator's model holds
 * a viscous friction in -x (the extended model's asymmetry) that makes the
 * force at the circle's speed four times the one the torque limit can drive,
 * so its compensation fails the controller's range check (|L F| <= tau_max,
 * docs/modules/ctrl.md) within the first periods (1-2 ms on the reference and
 * the heavy machine). Each stop counts 1 + the share of the run lost, from
 * the plants run here with the machine's identification on: compared exactly,
 * a stop counted as 2 fails too */
static void test_stop_is_failure(void **st)
{
    (void)st;
    for (int e = 0; e < 2; e++) {
        br_tune_delay_init(&g, ests[e]);
        const br_circle_cfg_t machine = br_circle_cfg_thesis(ests[e]);
        br_circle_cfg_t c = as_tuned(ests[e]);
        const double v_max_mps = br_circle_feed_mps(&c); /* each axis's largest speed */
        const double limit_N = BR_MACHINE_TORQUE_LIMIT_NM / BR_MACHINE_LEAD_MPRAD;
        est_of(&c, ests[e])->model.causes.dsigma2_neg_Nspm = (float)(4.0 * limit_N / v_max_mps);
        c.pf.load = (br_pf_load_t){0.0f, 0.0f}; /* the extended model: the PF's load needs the thesis one */
        double expected = 0.0;
        for (int k = 0; k < BR_TUNE_DELAY_N; k++) {
            br_circle_cfg_t p = g.plant[k];
            p.pf = c.pf;
            p.ukf = c.ukf;
            p.pf.est.delay_id = machine.pf.est.delay_id;
            p.ukf.est.delay_id = machine.ukf.est.delay_id;
            br_circle_result_t r;
            assert_int_equal(br_circle_run(&p, NULL, NULL, &r), 1);
            print_message("plant %d: stopped at %.3f s\n", k, r.fault_t_s);
            assert_true(r.fault_t_s > 0.0 && r.fault_t_s < p.duration_s);
            expected += 1.0 + (p.duration_s - r.fault_t_s) / p.duration_s;
        }
        const double failed = br_tune_delay_failed(&g, &c);
        print_message("%s, viscous %.4g N s/m in -x in its model: failed %.4f\n", e ? "PF" : "UKF",
                      (double)est_of(&c, ests[e])->model.causes.dsigma2_neg_Nspm, failed);
        assert_true(failed == expected);
        assert_true(failed > (double)BR_TUNE_DELAY_N);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_committed_runs),
        cmocka_unit_test(test_identification_on),
        cmocka_unit_test(test_stop_is_failure),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
