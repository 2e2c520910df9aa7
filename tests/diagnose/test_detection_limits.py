# SPDX-License-Identifier: Apache-2.0
"""The detection-limits study's statistics (sim/studies/detection_limits.py,
docs/detection-limits.md) on a stand-in diagnosis whose detections are known:
the bisection finds the smallest passing size of the ladder, tolerates as many
misses as the 95 % rate allows and no more, the proof requires every one of
its logs and steps up the ladder on a miss, and the Clopper-Pearson bounds are
the published ones; a cached result is reused only for the same diagnosis
code and br_simlog. No log is simulated: the study's `run` is replaced."""
import os
import re
import shutil
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "sim", "studies"))
import detection_limits as dl  # noqa: E402

CAUSE = "offset"
LAD = dl.GENERATORS[CAUSE][2]


class Stand:
    """Detects the cause when its size reaches `threshold`, except at the
    (ladder index, log index) pairs in `misses`; counts the logs it ran."""

    def __init__(self, threshold, misses=()):
        self.threshold, self.misses, self.calls = threshold, set(misses), []

    def __call__(self, simlog, work, key, flags, sigma, seed):
        _, _, si, j = key.rsplit("-", 3)
        size = float(flags[1])
        self.calls.append((int(si), int(j)))
        hit = size >= self.threshold and (int(si), int(j)) not in self.misses
        return ("found" if hit else "none"), ([CAUSE] if hit else [])


def bisect(stand, n=20, n_verify=59):
    saved = dl.run
    dl.run = stand
    try:
        _, _, _, out = dl.bisect_task(("simlog", "work", 0, "quiet", 0.02, 0, CAUSE, n, n_verify))
    finally:
        dl.run = saved
    return out


class Cache(unittest.TestCase):
    def test_digest_follows_the_diagnosis_code(self):
        with tempfile.TemporaryDirectory() as w:
            src = os.path.join(w, "python", "bristle", "diagnose")
            shutil.copytree(os.path.join(REPO, "python", "bristle", "diagnose"), src)
            saved = dl.REPO
            dl.REPO = w
            try:
                d0 = dl.code_digest()
                self.assertEqual(d0, dl.code_digest())
                with open(os.path.join(src, "selection.py"), "a") as f:
                    f.write("\n# another selection\n")
                self.assertNotEqual(d0, dl.code_digest())
            finally:
                dl.REPO = saved

    def test_a_result_of_other_code_is_not_reused(self):
        key, flags, sigma, seed = "quiet-offset-0-0", ["--offset", "0.001"], 0.02, 7
        saved = dict(dl.DIGEST), dict(dl.CACHE)
        try:
            dl.DIGEST["no-simlog"] = "old"
            dl.CACHE[f"{key}|{' '.join(flags)}|{sigma:.6g}|{seed}|old"] = ("offset", ["offset"])
            self.assertEqual(dl.run("no-simlog", "work", key, flags, sigma, seed), ("offset", ["offset"]))
            dl.DIGEST["no-simlog"] = "new"   # the code changed: the log is simulated again
            with self.assertRaises(FileNotFoundError):
                dl.run("no-simlog", "work", key, flags, sigma, seed)
        finally:
            dl.DIGEST.clear()
            dl.DIGEST.update(saved[0])
            dl.CACHE.clear()
            dl.CACHE.update(saved[1])


class Workers(unittest.TestCase):
    def test_a_task_returns_the_seconds_of_the_logs_it_ran(self):
        # a pool worker's USED and SECONDS are its own: they travel back with the result
        def fake(simlog, work, key, flags, sigma, seed):
            dl.USED.add(key)
            dl.SECONDS[key] = 1.5
            return "none", []
        saved = dl.run
        dl.run = fake
        try:
            r, used = dl._call((dl.nominal_task, ("s", "w", 0, "quiet", 0.02, "ident", 0, 2)))
        finally:
            dl.run = saved
        self.assertEqual(used, {"quiet-none-0": 1.5, "quiet-none-1": 1.5})
        self.assertEqual(r[0], "nominal")


class Statistics(unittest.TestCase):
    def test_clopper_pearson_bounds(self):
        self.assertAlmostEqual(dl.cp_lower(20, 20), 0.05 ** (1 / 20), places=9)
        self.assertGreaterEqual(dl.cp_lower(59, 59), 0.95)    # the proof's M = 59 reaches 95 %
        self.assertLess(dl.cp_lower(58, 58), 0.95)            # and 58 does not
        self.assertAlmostEqual(dl.cp_upper(0, 150), 1 - 0.05 ** (1 / 150), places=9)
        self.assertLessEqual(dl.cp_upper(0, 150), 0.02)       # the false-positive goal's 150 logs
        self.assertEqual(dl.cp_lower(0, 5), 0.0)
        self.assertEqual(dl.cp_upper(5, 5), 1.0)

    def test_misses_allowed_is_the_95_percent_rate(self):
        self.assertEqual(dl.misses_allowed(20), 1)
        self.assertEqual(dl.misses_allowed(19), 0)
        self.assertEqual(dl.misses_allowed(59), 2)
        self.assertEqual(dl.misses_allowed(100), 5)


class Bisection(unittest.TestCase):
    def test_limit_is_the_smallest_passing_size(self):
        for k in (0, 1, 5, 9, len(LAD) - 1):
            # a threshold between ladder sizes k-1 and k
            th = LAD[k] * 0.9 if k else LAD[0]
            out = bisect(Stand(th))
            self.assertEqual(out["limit_index"], k, k)
            self.assertEqual(out["proven_index"], k, k)
            failing = [p["size"] for p in out["probes"] if not p["passed"]]
            self.assertTrue(all(s < LAD[k] for s in failing))

    def test_above_the_ladder(self):
        out = bisect(Stand(LAD[-1] * 2))
        self.assertIsNone(out["limit"])
        self.assertIsNone(out["proven"])
        self.assertEqual(out["verify"], [])

    def test_one_miss_in_twenty_passes_two_fail(self):
        k = 7
        th = LAD[k] * 0.9
        out = bisect(Stand(th, misses={(k, 3)}), n_verify=0)
        self.assertEqual(out["limit_index"], k)
        at = next(p for p in out["probes"] if p["size"] == LAD[k])
        self.assertEqual((at["detected"], at["logs"]), (19, 20))
        out = bisect(Stand(th, misses={(k, 3), (k, 11)}), n_verify=0)
        self.assertEqual(out["limit_index"], k + 1)
        at = next(p for p in out["probes"] if p["size"] == LAD[k])
        # the size stops at its second miss
        self.assertEqual((at["detected"], at["logs"], at["passed"]), (10, 12, False))


class Options(unittest.TestCase):
    def test_a_proof_shorter_than_the_bisection_is_refused(self):
        # before any log is run (nothing is written into --work)
        import subprocess
        import tempfile
        with tempfile.TemporaryDirectory() as w:
            for bad in (["--n", "20", "--n-verify", "5"], ["--n-verify", "-1"]):
                r = subprocess.run([sys.executable, dl.__file__, "--simlog", "none", "--work", os.path.join(w, "x"),
                                    *bad], capture_output=True, text=True, timeout=120)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn("--n-verify", r.stderr)
                self.assertFalse(os.path.exists(os.path.join(w, "x")))


class Proof(unittest.TestCase):
    def test_proof_runs_every_log_and_reuses_none_it_should_not(self):
        k = 6
        st = Stand(LAD[k] * 0.9)
        out = bisect(st)
        self.assertEqual(out["proven_index"], k)
        pv = out["verify"][-1]
        self.assertEqual((pv["detected"], pv["logs"], pv["passed"]), (59, 59, True))
        # the proof's logs at the limit are the bisection's 20 plus 39 more (same keys, j = 0..58)
        self.assertEqual(sorted(j for si, j in st.calls if si == k and j >= 20), list(range(20, 59)))

    def test_a_miss_in_the_proof_steps_up(self):
        k = 6
        # one miss among the proof's extra logs at the limit: the bisection passes
        # it (1 of 20 allowed is not even used), the proof does not
        out = bisect(Stand(LAD[k] * 0.9, misses={(k, 40)}))
        self.assertEqual(out["limit_index"], k)
        self.assertEqual(out["proven_index"], k + 1)
        first, second = out["verify"]
        self.assertEqual((first["detected"], first["logs"], first["passed"]), (40, 41, False))
        self.assertEqual((second["detected"], second["logs"], second["passed"]), (59, 59, True))

    def test_proof_reported_in_the_summary_and_page(self):
        k = 4
        out = bisect(Stand(LAD[k] * 0.9, misses={(k, 25)}))
        res = {"cause": {(lv, CAUSE): dict(out) for lv in ("EMPS", "quiet")},
               "nominal": {lv: {("ident", 0, 1): [("none", [])]} for lv in ("EMPS", "quiet")}}
        s = dl.summarize(res, (("EMPS", 0.2), ("quiet", 0.02)), 20, 1, [CAUSE], 59)
        c = s["levels"]["quiet"]["causes"][CAUSE]
        self.assertAlmostEqual(c["proven_lower"], dl.cp_lower(59, 59))
        md, blocks = dl.markdown(s, "cmd", 1.0)
        self.assertEqual(blocks, {})
        row = next(line for line in md.splitlines() if line.startswith(f"| {CAUSE} | offset"))
        self.assertIn(f"**{dl._fmt(LAD[k + 1], 'N')}**: 59/59, ≥ {100 * dl.cp_lower(59, 59):.1f} % (1 size up from the limit)", row)
        self.assertTrue(re.search(r"at least 95 % at 95 % confidence", md))


PS = "presliding_hysteresis"


def summary(causes, kinds, misses=0):
    """A summary of a stand-in run of `causes` with one nominal chunk of each log kind (the first
    `misses` of its logs with a finding of presliding_hysteresis)."""
    out = bisect(Stand(LAD[5] * 0.9), n_verify=0)
    nom = [("presliding_hysteresis", [PS])] * misses + [("none", [])] * (10 - misses)
    res = {"cause": {(lv, c): dict(out) for lv in ("EMPS", "quiet") for c in causes},
           "nominal": {lv: {(k, 0, 10): nom for k in kinds} for lv in ("EMPS", "quiet")}}
    return dl.summarize(res, (("EMPS", 0.2), ("quiet", 0.02)), 20, 10, causes, 0)


class Presliding(unittest.TestCase):
    def test_its_logs_have_the_reversal_segment_and_a_scaled_element_set(self):
        _, _, lad, flags = dl.GENERATORS[PS]
        scale = dl.lugre_presliding_scale_m()
        import json
        with open(os.path.join(REPO, "machines", "reference.json")) as f:
            fr = json.load(f)["friction"]
        self.assertAlmostEqual(scale, fr["Fs_N"] / fr["sigma0_Npm"])
        f = dl.LOGS[dl.logs_of(PS)] + flags(2.0)
        self.assertEqual(f[:2], ["--reversals", "1"])
        d = [float(x) for x in f[f.index("--gms") + 1].split(",")]
        self.assertAlmostEqual(max(d), 2.0 * scale, delta=1e-6 * scale)
        self.assertEqual(len(d), len(dl.GMS_SHAPE))
        # the other causes keep the plain identification run
        self.assertEqual(dl.LOGS[dl.logs_of("offset")], [])

    def test_its_element_modes_have_lugres_damping_ratio_at_every_size(self):
        # the element damping of a ratio per element (br_simlog --gms-zeta): LuGre's bristle mode's on the
        # reference machine, sigma1 / (2 sqrt(sigma0 M)), M = m + J / (lead / 2 pi)^2, the same at every size
        import json
        import math
        with open(os.path.join(REPO, "machines", "reference.json")) as f:
            m = json.load(f)
        mech, fr = m["mechanics"], m["friction"]
        meff = mech["table_mass_kg"] + mech["inertia_kgm2"] * (2 * math.pi / mech["lead_m_per_rev"]) ** 2
        zeta = fr["sigma1_Nspm"] / (2 * math.sqrt(fr["sigma0_Npm"] * meff))
        _, _, lad, flags = dl.GENERATORS[PS]
        for size in (lad[0], lad[-1]):
            f = flags(size)
            self.assertAlmostEqual(float(f[f.index("--gms-zeta") + 1]), zeta, delta=1e-6 * zeta)
        # the ladder's top keeps d_max within the diagnosis's grid of breakaway displacements
        ps = dl.causes.get(PS)
        self.assertLessEqual(lad[-1] * dl.lugre_presliding_scale_m(), ps.GRID_MAX_M)

    def test_the_detections_presliding_m_against_the_plants(self):
        # a stand-in diagnosis that names the cause from size 0.5 on with half the plant's presliding_m
        # (as run() leaves it in LAST_PS_M); the block's table reports that ratio per probed size
        def stand(simlog, work, key, flags, sigma, seed):
            size = max(float(x) for x in flags[flags.index("--gms") + 1].split(",")) / dl.lugre_presliding_scale_m()
            if size < 0.5:
                return "none", []
            dl.LAST_PS_M[0] = 0.5 * dl.plant_presliding_m(size)
            return PS, [PS]
        self.assertAlmostEqual(dl.plant_presliding_m(1.0), 1.2 * dl.lugre_presliding_scale_m())
        saved = dl.run
        dl.run = stand
        try:
            _, _, _, out = dl.bisect_task(("simlog", "work", 0, "quiet", 0.02, 0, PS, 20, 59))
        finally:
            dl.run = saved
        res = {"cause": {(lv, PS): dict(out) for lv in ("EMPS", "quiet")}, "nominal": {}}
        s = dl.summarize(res, (("EMPS", 0.2), ("quiet", 0.02)), 20, 10, [PS], 59)
        table = "\n".join(dl.presliding_table(s))
        at = out["limit"]
        self.assertGreaterEqual(at, 0.5)
        # the proof's 59 logs at the limit, its first 20 the bisection's: counted once
        self.assertEqual(out["proven"], at)
        self.assertIn(f"{at:.3g}: {1e6 * dl.plant_presliding_m(at):.3g} um, 0.50 (0.50 .. 0.50), 59 |", table)
        below = max(p["size"] for p in out["probes"] if not p["passed"])
        self.assertIn(f"{below:.3g}: {1e6 * dl.plant_presliding_m(below):.3g} um, —", table)

    def test_nominal_logs_of_each_kind_the_causes_use(self):
        calls = []

        def fake_run(simlog, work, key, flags, sigma, seed):
            calls.append((key, tuple(flags), seed))
            return "none", []
        saved = dl.run
        dl.run = fake_run
        try:
            for kind in dl.LOGS:
                dl.nominal_task(("s", "w", 0, "quiet", 0.02, kind, 0, 2))
        finally:
            dl.run = saved
        # the identification logs keep their keys and seeds; the reversal logs have others
        self.assertEqual(calls[0], ("quiet-none-0", (), dl.hash_seed(0, 0, 0, 0)))
        self.assertEqual(calls[2][1], ("--reversals", "1"))
        self.assertNotIn(calls[2][0], {c[0] for c in calls[:2]})
        self.assertNotIn(calls[2][2], {c[2] for c in calls[:2]})

    def test_false_detections_counted_per_log_kind(self):
        s = summary([CAUSE, PS], list(dl.LOGS), misses=1)
        st = s["levels"]["quiet"]["nominal"]["ident with the reversal segment"]
        self.assertEqual((st["false_positives"], st["false_positive_causes"]), (1, {PS: 1}))
        self.assertAlmostEqual(st["false_positive_upper"], dl.cp_upper(1, 10))

    def test_a_run_of_the_block_alone_rewrites_only_its_block(self):
        main, blocks = dl.markdown(summary([CAUSE], ["ident"]), "make all", 1.0)
        page = dl.compose(None, main, blocks)
        self.assertNotIn(PS, page)
        m2, b2 = dl.markdown(summary([PS], ["ident with the reversal segment"], misses=2), "make ps", 1.0)
        self.assertIsNone(m2)
        page2 = dl.compose(page, m2, b2)
        self.assertTrue(page2.startswith(page.rstrip("\n")))       # the main part kept as it was
        blk = page2[page2.index(dl.BLOCK_BEGIN.format(PS, PS)):]
        self.assertIn("`make ps`", blk)
        self.assertIn("presliding_hysteresis 2", blk)                # its LuGre logs' false detections
        row = next(line for line in blk.splitlines() if line.startswith(f"| {PS} |"))
        self.assertIn("/", row)
        # again: the block replaced, not repeated; a full run replaces the main part and keeps the block
        page3 = dl.compose(page2, m2, b2)
        self.assertEqual(page3, page2)
        page4 = dl.compose(page3, main.replace("make all", "make again"), {})
        self.assertEqual(page4.count(dl.BLOCK_BEGIN.format(PS, PS)), 1)
        self.assertIn("make again", page4)
        self.assertIn("`make ps`", page4)


if __name__ == "__main__":
    unittest.main()
