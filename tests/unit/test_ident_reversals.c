/* SPDX-License-Identifier: Apache-2.0 */
/* The identification run's reversal segment (br_ident_add_reversals,
 * docs/simlog.md "The reversal segment"): its guards, the moves it appends,
 * and the reference it gives (slow reversals within the first 0.1 mm). */
#include "br_test.h"

#include <math.h>

#include "ident/br_ident.h"

static void test_guards(void **st)
{
    (void)st;
    const br_plant_cfg_t plant = br_plant_cfg_reference();
    br_ident_cfg_t c = br_ident_cfg_default(&plant);
    assert_int_equal(br_ident_add_reversals(&c, 0), -1);
    assert_int_equal(br_ident_add_reversals(&c, BR_IDENT_REV_MAX_PAIRS + 1), -1);
    assert_int_equal(c.n_moves, 4); /* a refused call appends nothing */
    /* moves that do not end at 0: the segment would start elsewhere */
    br_ident_cfg_t b = br_ident_cfg_backforth(&plant, 8.0);
    b.moves[1].x_to_m = 0.01;
    assert_int_equal(br_ident_add_reversals(&b, 1), -1);
    /* no room for the moves */
    c.n_moves = BR_IDENT_MAX_MOVES - 1;
    for (int i = 0; i < c.n_moves; i++) c.moves[i] = (br_move_t){0.0, 0.01, 0.0};
    assert_int_equal(br_ident_add_reversals(&c, 1), -1);
    assert_int_equal(c.n_moves, BR_IDENT_MAX_MOVES - 1);
}

static void test_segment(void **st)
{
    (void)st;
    const br_plant_cfg_t plant = br_plant_cfg_reference();
    const br_ident_cfg_t d = br_ident_cfg_default(&plant);
    br_ident_cfg_t c = d;
    assert_int_equal(br_ident_add_reversals(&c, 2), 0);
    assert_int_equal(c.n_moves, d.n_moves + 4);
    for (int i = 0; i < 4; i++) {
        const br_move_t *m = &c.moves[d.n_moves + i];
        assert_true(m->x_to_m == (i % 2 == 0 ? BR_IDENT_REV_AMP_M : 0.0));
        assert_true(m->v_max_mps == BR_IDENT_REV_SPEED_MPS);
        /* no rest at a turn; the cycle's rest after the last move */
        assert_true(m->dwell_s == (i == 3 ? d.moves[d.n_moves - 1].dwell_s : 0.0));
    }
    /* each pair adds 2 (amp / speed + speed / acc) per cycle, plus the moved rest */
    const double pair_s = 2.0 * (BR_IDENT_REV_AMP_M / BR_IDENT_REV_SPEED_MPS + BR_IDENT_REV_SPEED_MPS / c.acc_mps2);
    const double added = br_ident_duration_s(&c) - br_ident_duration_s(&d);
    assert_true(fabs(added - d.cycles * (2.0 * pair_s + d.moves[d.n_moves - 1].dwell_s)) < 1e-9);
    /* the reference during the segment stays in [0, amp] and moves no faster than its speed */
    /* the first cycle's segment starts at its end */
    const double t0 = d.dwell0_s + (br_ident_duration_s(&d) - d.dwell0_s) / d.cycles;
    double prev = br_ident_ref_m(&c, t0), top = 0.0;
    for (double t = t0 + 1e-3; t < t0 + 2.0 * pair_s; t += 1e-3) {
        const double r = br_ident_ref_m(&c, t);
        assert_true(r >= -1e-15 && r <= BR_IDENT_REV_AMP_M + 1e-15);
        assert_true(fabs(r - prev) <= BR_IDENT_REV_SPEED_MPS * 1e-3 + 1e-15);
        top = fmax(top, r);
        prev = r;
    }
    /* the turn reached, within one period's travel of the 1 ms samples */
    assert_true(fabs(top - BR_IDENT_REV_AMP_M) <= BR_IDENT_REV_SPEED_MPS * 1e-3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_guards),
        cmocka_unit_test(test_segment),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
