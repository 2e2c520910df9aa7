# SPDX-License-Identifier: Apache-2.0
"""The selection's rules stated on constructed inputs (python/bristle/diagnose/
selection.py; docs/diagnose.md "Significance", "Ranking", "Borderline"), no
log and no fit, about a second:

- the levels are docs/diagnose.md's: each is read from the doc's text;
- the gate's two levels (gain >= 5 % at p < 0.01, or gain >= 25 % at
  p < 0.05) and the backward step's (gain >= 5 % at p < 0.05) at their
  edges, on Candidates whose relerr and p are given;
- the block test: 10 blocks, all improving -> p = 2^-10; no block changed -> 1;
- `test` refits with the shape only from REFINE_GAIN on; `without` and
  `backward` on a joint model of three causes;
- the backward step in `diagnose`: an offset that stood in for the mean
  force of two causes found after it is dropped once both are in, recorded
  with its round, and not tested again;
- the backward step's guard (`worse_than`): a drop that would leave a model
  worse than the round's start, and not better in the blocks, is refused;
- pairs: tested only when no cause is significant alone and one gains
  MIN_REL_GAIN; a pair that hides each other is found as two findings; a
  pair with a member it does not need is no finding;
- `borderline`: the last round's causes, not significant and not in the
  model, at the looser level, its edges included.

The joint-model tests run `selection` against a small world of known
explained shares (World below: which share of the held-out residual each
cause takes away) in place of the force model, so that the outcome of
every round is known in advance; the selection with the real model on
synthetic logs is test_selection.py's.
"""
import os
import re
import sys
import types
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "python"))
from bristle.diagnose import causes, selection  # noqa: E402


def doc_text():
    with open(os.path.join(REPO, "docs", "diagnose.md")) as f:
        return " ".join(f.read().split())  # one space for every line break


def doc_number(pattern, text):
    m = re.search(pattern, text)
    if m is None:
        raise AssertionError(f"docs/diagnose.md no longer says {pattern!r}")
    return [float(g) for g in m.groups()]


class LevelsAreTheDocsTest(unittest.TestCase):
    """Each level of selection.py against the sentence of docs/diagnose.md
    that states it (percent in the doc, fractions in the code)."""

    @classmethod
    def setUpClass(cls):
        cls.doc = doc_text()

    def test_significance(self):
        gain, = doc_number(r"held-out relerr is at least ([\d.]+) % \(relative\) below", self.doc)
        self.assertEqual(selection.MIN_REL_GAIN, gain / 100)
        blocks, = doc_number(r"cut into (\d+) consecutive blocks", self.doc)
        self.assertEqual(selection.N_BLOCKS, blocks)
        p, = doc_number(r"signed-rank test at p < ([\d.]+)", self.doc)
        self.assertEqual(selection.P_MAX, p)
        strong, p_strong = doc_number(r"A gain of at least ([\d.]+) % needs only p < ([\d.]+)", self.doc)
        self.assertEqual(selection.STRONG_GAIN, strong / 100)
        self.assertEqual(selection.P_STRONG, p_strong)
        refine, = doc_number(r"shape-held gain reaches ([\d.]+) %", self.doc)
        self.assertEqual(selection.REFINE_GAIN, refine / 100)

    def test_backward_and_borderline(self):
        gain, p = doc_number(r"no longer gains ([\d.]+) % at p < ([\d.]+)", self.doc)
        self.assertEqual(selection.MIN_REL_GAIN, gain / 100)
        self.assertEqual(selection.P_REMOVE, p)
        gain, p = doc_number(r"Borderline\*\*: a cause of the last round that gains at least ([\d.]+) % with "
                             r"p < ([\d.]+)", self.doc)
        self.assertEqual(selection.BORDERLINE_GAIN, gain / 100)
        self.assertEqual(selection.BORDERLINE_P, p)


def cand(gain, p, base=1.0):
    """A Candidate with held-out relerr base (1 - gain) against base."""
    return selection.Candidate("offset", None, base, base * (1.0 - gain), p)


class GateTest(unittest.TestCase):
    """Candidate.significant and .kept at the edges of their levels."""

    def test_gain_is_relative(self):
        c = selection.Candidate("offset", None, 4.0, 3.0, 0.5)
        self.assertEqual(c.rel_gain, 0.25)
        self.assertEqual((c.base_relerr, c.relerr, c.p_value), (4.0, 3.0, 0.5))
        # no base error to explain: no gain (and no division by zero)
        c = selection.Candidate("offset", None, 0.0, 0.0, 1e-9)
        self.assertEqual(c.rel_gain, 0.0)
        self.assertFalse(c.significant)
        self.assertFalse(c.kept)

    def test_first_level(self):
        g, p = selection.MIN_REL_GAIN, selection.P_MAX
        self.assertTrue(cand(g * 1.001, p * 0.999).significant)
        self.assertFalse(cand(g * 0.999, 1e-9).significant)       # too small a gain, however consistent
        self.assertFalse(cand(g * 1.001, p).significant)          # p must be below the level
        self.assertFalse(cand(g * 1.001, p * 1.001).significant)
        # between the levels' p: the first level's gain is not enough
        self.assertFalse(cand(0.2, 0.5 * (p + selection.P_STRONG)).significant)

    def test_strong_level(self):
        g, p = selection.STRONG_GAIN, selection.P_STRONG
        self.assertGreater(p, selection.P_MAX)  # the point of the second level: less consistency
        self.assertEqual(cand(g, 0.5).rel_gain, g)  # 1 - 0.75 is exact: the edge itself
        self.assertTrue(cand(g, p * 0.999).significant)            # at least 25 %: the edge counts
        self.assertTrue(cand(0.9, p * 0.999).significant)
        self.assertFalse(cand(g * 0.999, p * 0.999).significant)
        self.assertFalse(cand(g, p).significant)
        self.assertFalse(cand(0.9, p * 1.001).significant)

    def test_kept_level(self):
        g, p = selection.MIN_REL_GAIN, selection.P_REMOVE
        self.assertGreater(p, selection.P_MAX)  # looser than to enter
        self.assertTrue(cand(g * 1.001, p * 0.999).kept)
        self.assertFalse(cand(g * 1.001, p * 0.999).significant)  # kept, although it would not enter
        self.assertFalse(cand(g * 1.001, p).kept)
        self.assertFalse(cand(g * 0.999, 1e-9).kept)
        self.assertFalse(cand(0.0, 1e-9).kept)
        self.assertTrue(cand(0.5, 1e-9).kept)


class BlockTest(unittest.TestCase):
    P = types.SimpleNamespace(test=slice(50, 250))

    def test_blocks(self):
        rng = np.random.default_rng(5)
        e = rng.normal(size=250)
        # every block better: the smallest one-sided signed-rank p, 2^-N over N blocks
        self.assertAlmostEqual(selection.block_p_value(self.P, e, 0.5 * e), 2.0 ** -selection.N_BLOCKS, places=12)
        # the blocks are of the held-out part: what the training part does is not seen
        e_new = 0.5 * e
        e_new[:50] = 10.0 * e[:50]
        self.assertAlmostEqual(selection.block_p_value(self.P, e, e_new), 2.0 ** -selection.N_BLOCKS, places=12)
        # one block of N better, the others the same
        e_new = e.copy()
        e_new[50:70] *= 0.5
        one = selection.block_p_value(self.P, e, e_new)
        self.assertGreater(one, selection.P_STRONG)
        # nothing changes: p = 1
        self.assertEqual(selection.block_p_value(self.P, e, e.copy()), 1.0)
        # every block worse: p = 1 too
        self.assertEqual(selection.block_p_value(self.P, 0.5 * e, e), 1.0)


class World:
    """A held-out residual made of named shares, and which shares each cause
    takes away: a Fit's residual is the noise plus every share none of its
    causes takes. Stands in for model.py (the same functions, recorded)."""

    N = 300
    TEST = slice(100, 300)
    SOME = (0, 3, 6)

    def __init__(self, takes, sizes, seed=7):
        rng = np.random.default_rng(seed)
        self.takes = takes
        # each share: in every block of the held-out part, different shapes; a name
        # ending in "*" only in the held-out part's first block (a gain there is not consistent)
        self.share = {k: s * (1.0 + 0.3 * rng.uniform(size=self.N)) * np.sign(rng.normal(size=self.N))
                      for k, s in sizes.items()}
        # a name ending in "~" only in the held-out blocks SOME (three of ten: no consistent gain either way)
        blk = np.array_split(np.arange(self.TEST.start, self.TEST.stop), selection.N_BLOCKS)
        for k in self.share:
            if k.endswith("*"):
                self.share[k][:self.TEST.start] = 0.0
                self.share[k][self.TEST.start + (self.TEST.stop - self.TEST.start) // selection.N_BLOCKS:] = 0.0
            if k.endswith("~"):
                keep = np.concatenate([blk[b] for b in self.SOME])
                mask = np.zeros(self.N, bool)
                mask[keep] = True
                self.share[k][~mask] = 0.0
        self.noise = 0.01 * rng.normal(size=self.N)
        self.y = 10.0 * np.ones(self.N)
        self.prep = types.SimpleNamespace(test=self.TEST, train=slice(0, 100))
        self.calls = []
        world = self

        class Fit:
            def __init__(self, causes_in, nl=None, shape=("shape",)):
                self.causes, self.shape = tuple(causes_in), shape
                self.nl = dict(nl) if nl is not None else {
                    k: 1.0 for c in self.causes for k in causes.get(c).NL}

            def residual(self, prep):
                # a share under a tuple of causes is taken only by all of them together,
                # none of those marked "!" in the model (a joint fit a stand-in spoils)
                def takes(k):
                    if isinstance(k, str):
                        return k in self.causes
                    return all((c[1:] not in self.causes) if c.startswith("!") else (c in self.causes) for c in k)
                taken = {s for k, v in world.takes.items() for s in v if takes(k)}
                left = set(world.share) - taken
                return world.noise + sum((world.share[k] for k in sorted(left)), np.zeros(world.N))

            def relerr(self, prep, sl):
                return 100.0 * float(np.linalg.norm(self.residual(prep)[sl]) / np.linalg.norm(world.y[sl]))

            def cause_params(self, cause):
                return {}

        self.Fit = Fit

        def refine(prep, fit, rounds=2, max_nfev=40):
            self.calls.append(("refine", fit.causes, rounds))
            return Fit(fit.causes, fit.nl, fit.shape)

        def solve(prep, shape, causes_in, nl):
            self.calls.append(("solve", tuple(causes_in), shape, dict(nl)))
            return Fit(causes_in, nl, shape)

        self.model = types.SimpleNamespace(
            fit_nominal=lambda prep: Fit(()),
            add_cause=lambda prep, base, cause: Fit(base.causes + (cause,)),
            refine=refine, solve=solve)


class WorldTest(unittest.TestCase):
    def use(self, world):
        saved = selection.model
        selection.model = world.model
        self.addCleanup(setattr, selection, "model", saved)
        return world


# An offset that stands in for the mean force of two causes (docs/diagnose.md,
# "Backward step"): it takes both their mean shares, so in round 1 it gains
# more than either; each of them takes its mean and its own share.
STAND_IN = {"offset": ("mean_a", "mean_d"),
            "asymmetric_friction": ("mean_a", "own_a"),
            "actuator_delay": ("mean_d", "own_d")}
STAND_IN_SIZES = {"mean_a": 1.0, "mean_d": 1.0, "own_a": 0.4, "own_d": 0.35}


class RefineGateTest(WorldTest):
    def test_refit_with_the_shape_from_refine_gain_on(self):
        g = selection.REFINE_GAIN
        for gain, refined in ((g * 0.5, False), (g * 2.0, True), (0.5, True)):
            # the cause takes a share whose removal gains `gain`: ||r||^2 = ||n||^2 (1 - (1 - gain)^2)
            w = World({"offset": ("s",)}, {"s": 1.0})
            n = np.linalg.norm(w.noise[w.TEST])
            r = w.share["s"]
            r *= n * np.sqrt(1.0 / (1.0 - gain) ** 2 - 1.0) / np.linalg.norm(r[w.TEST])
            w.noise[w.TEST] -= r[w.TEST] * (w.noise[w.TEST] @ r[w.TEST]) / (r[w.TEST] @ r[w.TEST])
            self.use(w)
            base = w.Fit(())
            c = selection.test(w.prep, base, "offset")
            self.assertAlmostEqual(c.rel_gain, gain, delta=0.02 * gain)
            self.assertEqual(c.base_relerr, base.relerr(w.prep, w.TEST))
            ref = [x for x in w.calls if x[0] == "refine"]
            self.assertEqual(bool(ref), refined, gain)
            if refined:  # the refitted model is the one measured and returned
                self.assertEqual(ref, [("refine", ("offset",), 1)])

    def test_a_cause_that_cannot_be_fitted_is_no_candidate(self):
        w = self.use(World({}, {"s": 1.0}))
        w.model.add_cause = lambda prep, base, cause: None
        self.assertIsNone(selection.test(w.prep, w.Fit(()), "offset"))


class BackwardTest(WorldTest):
    def test_without(self):
        w = self.use(World(STAND_IN, STAND_IN_SIZES))
        joint = w.Fit(("offset", "asymmetric_friction", "actuator_delay"), shape=("joint",))
        for c in joint.causes:
            w.calls.clear()
            rest = selection.without(w.prep, joint, c)
            left = tuple(x for x in joint.causes if x != c)
            self.assertEqual(rest.causes, left)
            # the cause's own nonlinear parameters go, the others' stay
            self.assertEqual(set(rest.nl), {k for x in left for k in causes.get(x).NL})
            self.assertFalse(set(rest.nl) & set(causes.get(c).NL))
            # solved from the joint model's shape, then refitted (at least one round)
            self.assertEqual(w.calls[0][:3], ("solve", left, ("joint",)))
            self.assertEqual(w.calls[-1][:2], ("refine", left))
            self.assertGreaterEqual(w.calls[-1][2], 1)
        # a cause named by its value (read from a file, a command line), not by the registry's object
        name = "".join(["actuator", "_", "delay"])
        self.assertIsNot(name, "actuator_delay")
        self.assertEqual(selection.without(w.prep, joint, name).causes, ("offset", "asymmetric_friction"))

    def test_backward_candidates(self):
        w = self.use(World(STAND_IN, STAND_IN_SIZES))
        joint = w.Fit(("offset", "asymmetric_friction", "actuator_delay"))
        te = w.TEST
        back = selection.backward(w.prep, joint)
        self.assertEqual([b.cause for b in back], list(joint.causes))
        for b in back:
            # each cause against the joint model without it
            self.assertEqual(b.base.causes, tuple(x for x in joint.causes if x != b.cause))
            self.assertIs(b.fit, joint)
            self.assertEqual(b.relerr, joint.relerr(w.prep, te))
            self.assertEqual(b.base_relerr, b.base.relerr(w.prep, te))
            self.assertEqual(b.p_value, selection.block_p_value(w.prep, b.base.residual(w.prep),
                                                                joint.residual(w.prep)))
        by = {b.cause: b for b in back}
        # the offset is no longer needed: leaving it out changes nothing
        self.assertAlmostEqual(by["offset"].rel_gain, 0.0, places=12)
        self.assertEqual(by["offset"].p_value, 1.0)
        self.assertFalse(by["offset"].kept)
        for c in ("asymmetric_friction", "actuator_delay"):
            self.assertTrue(by[c].kept, c)
            self.assertGreater(by[c].rel_gain, 0.5)


class DiagnoseBackwardStepTest(WorldTest):
    def test_a_stand_in_is_dropped(self):
        w = self.use(World(STAND_IN, STAND_IN_SIZES))
        msgs = []
        d = selection.diagnose(w.prep, msgs.append)
        found = [[c["cause"] for c in r if c["significant"]] for r in d.rounds]
        # round 1: the stand-in gains most (both means) and is the first finding
        r1 = {c["cause"]: c for c in d.rounds[0]}
        self.assertEqual(set(r1), set(causes.NAMES))
        self.assertEqual(max(d.rounds[0], key=lambda c: c["relative_gain"])["cause"], "offset")
        self.assertIn("offset", found[0])
        # the others enter against the joint model, strongest first
        self.assertEqual([f[0].cause for f in d.findings], ["asymmetric_friction", "actuator_delay"])
        # with both in, the offset is left out of the joint model: dropped in round 3, its
        # gain there (0: the two take its whole share) in the record
        self.assertEqual(len(d.dropped), 1)
        self.assertEqual(d.dropped[0]["cause"], "offset")
        self.assertEqual(d.dropped[0]["round"], 3)
        self.assertLess(d.dropped[0]["relative_gain"], selection.MIN_REL_GAIN)
        self.assertFalse(d.dropped[0]["significant"])
        # not dropped before: in round 2 the joint model still needed it
        self.assertEqual(len(d.rounds), 4)
        # a dropped cause is not tested again; the last round has nothing significant
        self.assertNotIn("offset", {c["cause"] for c in d.rounds[3]})
        self.assertEqual(found[3], [])
        # the model is the two causes, refitted after the drop
        self.assertEqual(set(d.extended.causes), {"asymmetric_friction", "actuator_delay"})
        pair = ("asymmetric_friction", "actuator_delay")
        left_out = next(i for i, x in enumerate(w.calls) if x[:2] == ("solve", pair))
        self.assertIn(("refine", pair, 2), w.calls[left_out:])  # the full refit, not the leave-out's
        self.assertLess(d.extended.relerr(w.prep, w.TEST), 0.2 * d.nominal.relerr(w.prep, w.TEST))
        drop = [m for m in msgs if m.startswith("  dropped ")]
        self.assertEqual(len(drop), 1)
        self.assertTrue(drop[0].startswith("  dropped offset: left out of the joint model"))
        rec = d.dropped[0]
        self.assertIn(f"held-out relerr {rec['base_relerr_percent']:.3f} % against {rec['relerr_percent']:.3f} %",
                      drop[0])
        self.assertIn(f"(gain {100 * rec['relative_gain']:.1f} %, p = {rec['p_value']:.2g})", drop[0])

    def test_without_a_stand_in_nothing_is_dropped(self):
        # the offset takes only its own share: every finding stays
        takes = {"offset": ("o",), "asymmetric_friction": ("a",), "actuator_delay": ("d",)}
        w = self.use(World(takes, {"o": 1.0, "a": 0.7, "d": 0.5}))
        d = selection.diagnose(w.prep)
        self.assertEqual([f[0].cause for f in d.findings], ["offset", "asymmetric_friction", "actuator_delay"])
        self.assertEqual(d.dropped, [])
        self.assertEqual(set(d.extended.causes), set(takes))

    def test_a_finding_left_with_one_block_is_dropped(self):
        # the offset gains most in round 1 (with a share confined to one block); once the
        # ripple takes the rest, what the offset adds is that one block: not consistent,
        # dropped although two causes are left
        takes = {"offset": ("m", "q*"), "position_ripple": ("m", "b")}
        w = self.use(World(takes, {"m": 1.0, "q*": 2.0, "b": 0.5}))
        msgs = []
        d = selection.diagnose(w.prep, msgs.append)
        self.assertEqual(max(d.rounds[0], key=lambda c: c["relative_gain"])["cause"], "offset")
        self.assertEqual([x["cause"] for x in d.dropped], ["offset"])
        self.assertEqual(d.dropped[0]["round"], 2)
        self.assertGreater(d.dropped[0]["relative_gain"], selection.MIN_REL_GAIN)  # a gain, inconsistent
        self.assertGreaterEqual(d.dropped[0]["p_value"], selection.P_REMOVE)
        self.assertEqual([f[0].cause for f in d.findings], ["position_ripple"])
        self.assertEqual(d.extended.causes, ("position_ripple",))
        drop, = [m for m in msgs if m.startswith("  dropped ")]
        self.assertIn(f"(gain {100 * d.dropped[0]['relative_gain']:.1f} %, p = {d.dropped[0]['p_value']:.2g})", drop)

    def test_a_drop_that_would_leave_a_worse_model_is_refused(self):
        # the offset enters first (its share m and a large share o~ in three blocks of
        # ten), asymmetric friction then takes a against it. Without the offset the
        # joint model loses o~: a gain in three blocks, not kept at P_REMOVE. But the
        # model left (asymmetric friction alone) is worse than the round's start (the
        # offset alone), and not better in the blocks either: the drop is refused, the
        # joint model stays (docs/diagnose.md "Backward step").
        takes = {"offset": ("m", "o~"), "asymmetric_friction": ("m", "a")}
        w = self.use(World(takes, {"m": 1.0, "o~": 2.5, "a": 0.5}))
        msgs = []
        d = selection.diagnose(w.prep, msgs.append)
        self.assertEqual([f[0].cause for f in d.findings], ["offset", "asymmetric_friction"])
        self.assertEqual(d.dropped, [])
        self.assertEqual(set(d.extended.causes), set(takes))
        # what the guard saw: the offset's removal is weak (not kept) ...
        joint = w.Fit(("offset", "asymmetric_friction"))
        by = {b.cause: b for b in selection.backward(w.prep, joint)}
        self.assertFalse(by["offset"].kept)
        self.assertGreaterEqual(by["offset"].p_value, selection.P_REMOVE)
        # ... and leaves a model worse than the round's start, not better in the blocks
        left, start = w.Fit(("asymmetric_friction",)), w.Fit(("offset",))
        self.assertGreater(left.relerr(w.prep, w.TEST), start.relerr(w.prep, w.TEST))
        self.assertGreaterEqual(selection.block_p_value(w.prep, start.residual(w.prep), left.residual(w.prep)),
                                selection.P_REMOVE)
        self.assertTrue(selection.worse_than(w.prep, left, start))
        kept, = [m for m in msgs if m.startswith("  kept ")]
        self.assertTrue(kept.startswith("  kept offset: without it the held-out relerr"))

    def test_worse_than(self):
        w = self.use(World({"offset": ("o",), "position_ripple": ("r*",)}, {"o": 1.0, "r*": 4.0}))
        none, off, rip = w.Fit(()), w.Fit(("offset",)), w.Fit(("position_ripple",))
        # a lower or equal held-out relerr is never worse
        self.assertFalse(selection.worse_than(w.prep, off, off))
        self.assertFalse(selection.worse_than(w.prep, off, none))
        # higher, and not better in the blocks: worse
        self.assertGreater(none.relerr(w.prep, w.TEST), off.relerr(w.prep, w.TEST))
        self.assertTrue(selection.worse_than(w.prep, none, off))
        # lower, though worse in nine blocks of ten (better by far in one): never worse
        self.assertGreater(selection.block_p_value(w.prep, off.residual(w.prep), rip.residual(w.prep)),
                           selection.P_REMOVE)
        self.assertFalse(selection.worse_than(w.prep, rip, off))
        # higher (the one block r*), but better in nine blocks of ten: not worse
        self.assertGreater(off.relerr(w.prep, w.TEST), rip.relerr(w.prep, w.TEST))
        self.assertLess(selection.block_p_value(w.prep, rip.residual(w.prep), off.residual(w.prep)),
                        selection.P_REMOVE)
        self.assertFalse(selection.worse_than(w.prep, off, rip))

    def test_the_weakest_goes_first(self):
        # with all four in, two findings are not needed: the offset gains nothing (the
        # others take its three shares), the ripple a gain confined to one block. The
        # weaker (the offset) is dropped first; without it the ripple is needed again.
        takes = {"offset": ("s", "t", "x"),
                 "position_ripple": ("s", "u", "sm*"),
                 "asymmetric_friction": ("t", "u", "v"),
                 "actuator_delay": ("w", "x")}
        sizes = {"s": 1.0, "t": 1.0, "x": 1.0, "u": 0.7, "sm*": 2.0, "v": 0.45, "w": 0.55}
        w = self.use(World(takes, sizes))
        d = selection.diagnose(w.prep)
        order = [c for r in d.rounds for c in [max(r, key=lambda c: c["relative_gain"])["cause"]]]
        self.assertEqual(order[:4], ["offset", "position_ripple", "actuator_delay", "asymmetric_friction"])
        self.assertEqual([x["cause"] for x in d.dropped], ["offset"])
        self.assertEqual(d.dropped[0]["round"], 4)
        self.assertEqual([f[0].cause for f in d.findings],
                         ["position_ripple", "actuator_delay", "asymmetric_friction"])


class PairTest(WorldTest):
    # an offset and a gradient that hide each other: each alone takes a share in three
    # blocks of ten (a visible gain, not consistent); together they also take j, in every block
    HIDING = {"offset": ("o~",), "position_gradient": ("g~",), ("offset", "position_gradient"): ("j",)}
    SIZES = {"o~": 1.0, "g~": 1.0, "j": 0.3}

    def test_pairs_to_test(self):
        rem = ["offset", "asymmetric_friction", "position_gradient", "actuator_delay"]
        cs = [cand(selection.MIN_REL_GAIN, 0.5), cand(selection.MIN_REL_GAIN * 0.999, 0.5)]
        cs[0].cause, cs[1].cause = "position_gradient", "actuator_delay"
        # a cause gaining MIN_REL_GAIN alone seeds pairs with every other; each pair once
        self.assertEqual(selection.pairs_to_test(cs, rem),
                         [("offset", "position_gradient"), ("asymmetric_friction", "position_gradient"),
                          ("position_gradient", "actuator_delay")])
        # no cause gains MIN_REL_GAIN alone: no pair
        self.assertEqual(selection.pairs_to_test(cs[1:], rem), [])

    def test_a_hidden_pair_is_found(self):
        w = self.use(World(self.HIDING, self.SIZES))
        msgs = []
        d = selection.diagnose(w.prep, msgs.append)
        r1 = {c["cause"]: c for c in d.rounds[0]}
        # alone: a visible gain, not significant
        for c in ("offset", "position_gradient"):
            self.assertGreaterEqual(r1[c]["relative_gain"], selection.MIN_REL_GAIN)
            self.assertFalse(r1[c]["significant"])
        self.assertFalse(any(c["significant"] for c in d.rounds[0]))
        # together: significant, both findings, both kept by the backward step
        self.assertEqual([f[0].cause for f in d.findings], ["offset", "position_gradient"])
        self.assertEqual(set(d.extended.causes), {"offset", "position_gradient"})
        self.assertEqual(d.dropped, [])
        sig = [p for p in d.pairs if p["significant"]]
        self.assertEqual([p["causes"] for p in sig], [["offset", "position_gradient"]])
        self.assertEqual(sig[0]["round"], 1)
        # each finding carries the pair's measures against the nominal model
        for cnd, fit in d.findings:
            self.assertEqual(cnd.base_relerr, d.nominal.relerr(w.prep, w.TEST))
            self.assertEqual(cnd.p_value, sig[0]["p_value"])
        self.assertTrue(any(m.startswith("finding 2: offset and position_gradient") for m in msgs))
        # the pairs tested: each seed with every other cause, once
        self.assertEqual(len(d.pairs), len(causes.NAMES) * (len(causes.NAMES) - 1) // 2
                         - (len(causes.NAMES) - 2) * (len(causes.NAMES) - 3) // 2)

    def test_a_pair_with_a_member_it_does_not_need_is_not_a_finding(self):
        # the ripple gains visibly alone (r~, three blocks of ten: not consistent); the pair
        # with the gradient passes the gate only through the gradient's small share g, in
        # every block, worth less than MIN_REL_GAIN in the pair's model: the gradient is not
        # needed there, so the pair is no finding (the ripple alone is what is tested, and
        # it is not significant). EMPS: ripple + gradient, the gradient not needed.
        w = self.use(World({"position_ripple": ("r~",), "position_gradient": ("g",)},
                           {"r~": 1.0, "g": 0.003}))
        d = selection.diagnose(w.prep)
        pr, = [p for p in d.pairs if p["causes"] == ["position_ripple", "position_gradient"]]
        self.assertTrue(selection.Candidate("x", None, pr["base_relerr_percent"], pr["relerr_percent"],
                                            pr["p_value"]).significant)   # the gate alone would pass
        self.assertFalse(pr["needed"]["position_gradient"])
        self.assertFalse(pr["significant"])
        self.assertEqual((d.findings, d.extended.causes), ([], ()))
        self.assertFalse(any(p["significant"] for p in d.pairs))

    def test_a_pair_not_checked_for_need_is_not_significant(self):
        # the gate alone passes; until each member's need is measured the pair is no finding
        pc = selection.PairCandidate(("offset", "position_gradient"), None, 1.0, 0.5, 1e-6)
        self.assertTrue(pc.gate)
        self.assertFalse(pc.significant)
        both = {"offset": True, "position_gradient": True}
        self.assertTrue(selection.PairCandidate(("offset", "position_gradient"), None, 1.0, 0.5, 1e-6, both)
                        .significant)
        one = dict(both, position_gradient=False)
        self.assertFalse(selection.PairCandidate(("offset", "position_gradient"), None, 1.0, 0.5, 1e-6, one)
                         .significant)
        # need does not make a pair that fails the gate significant
        self.assertFalse(selection.PairCandidate(("offset", "position_gradient"), None, 1.0, 0.99, 1e-6, both)
                         .significant)

    def test_a_pair_is_refitted_once_with_the_shape(self):
        w = self.use(World(self.HIDING, self.SIZES))
        base = w.Fit(())
        c = selection.test_pair(w.prep, base, ("offset", "position_gradient"))
        self.assertEqual(c.pair, ("offset", "position_gradient"))
        self.assertEqual(c.cause, "offset+position_gradient")
        self.assertEqual(w.calls[0], ("refine", ("offset", "position_gradient"), 1))
        # the members' need: each left out of the pair's model (solved, then refitted)
        self.assertEqual(c.needed, {"offset": True, "position_gradient": True})

    def test_pair_messages(self):
        w = self.use(World(self.HIDING, self.SIZES))
        msgs = []
        d = selection.diagnose(w.prep, msgs.append)
        for pr in d.pairs:
            line, = [m for m in msgs if m.startswith("  " + "+".join(pr["causes"]) + " ")]
            self.assertIn(f"held-out relerr {pr['relerr_percent']:.3f} % (gain {100 * pr['relative_gain']:.1f} %, "
                          f"p = {pr['p_value']:.2g})", line)
            self.assertEqual(line.endswith(" significant"), pr["significant"])

    def test_without_a_visible_gain_no_pair_is_tested(self):
        # the pair's share alone, each cause gaining nothing by itself: no pair is tried
        w = self.use(World({("offset", "position_gradient"): ("j",)}, {"j": 0.3}))
        d = selection.diagnose(w.prep)
        self.assertEqual((d.findings, d.pairs), ([], []))
        self.assertEqual(len(d.rounds), 1)


class SwapTest(WorldTest):
    # asymmetric friction stands in for the offset (its share m, and a hair more); with
    # it in the model the offset adds nothing (their joint fit spoils k); the gradient
    # and the offset together take k
    STAND_IN = {"offset": ("m",), "asymmetric_friction": ("m", "a"), "position_gradient": ("g",),
                ("offset", "position_gradient", "!asymmetric_friction"): ("k",)}

    def test_a_stand_in_is_swapped_for_the_cause(self):
        w = self.use(World(self.STAND_IN, {"m": 1.0, "a": 0.15, "g": 0.6, "k": 0.4}))
        msgs = []
        d = selection.diagnose(w.prep, msgs.append)
        r1 = {c["cause"]: c for c in d.rounds[0]}
        self.assertGreater(r1["asymmetric_friction"]["relative_gain"], r1["offset"]["relative_gain"])
        found = [m.split(": ")[1].split(",")[0] for m in msgs if m.startswith("finding ")]
        self.assertEqual(sorted(found), ["asymmetric_friction", "position_gradient"])
        # the offset takes the stand-in's place; the stand-in is not tested again
        self.assertEqual([f[0].cause for f in d.findings],
                         ["offset" if c == "asymmetric_friction" else c for c in found])
        self.assertEqual(set(d.extended.causes), {"offset", "position_gradient"})
        sw, = d.swapped
        self.assertEqual((sw["cause"], sw["out"], sw["round"]), ("offset", "asymmetric_friction", 3))
        self.assertTrue(sw["significant"])
        self.assertTrue(all("asymmetric_friction" not in {c["cause"] for c in r} for r in d.rounds[3:]))
        # in round 3 the offset added nothing beside the stand-in: only the swap finds it
        r3 = {c["cause"]: c for c in d.rounds[2]}
        self.assertFalse(r3["offset"]["significant"])
        self.assertTrue(any(m.startswith("swapped asymmetric_friction for offset") for m in msgs))
        self.assertLess(d.extended.relerr(w.prep, w.TEST), 0.5 * sw["base_relerr_percent"])

    def test_swaps(self):
        w = self.use(World(self.STAND_IN, {"m": 1.0, "a": 0.15, "g": 0.6, "k": 0.4}))
        fit = w.Fit(("asymmetric_friction", "position_gradient"))
        rem = ["offset", "actuator_delay"]
        sw = selection.swaps(w.prep, fit, rem)
        # each finding out, each remaining cause in, measured against the model itself
        self.assertEqual([(c.out, c.cause) for c in sw],
                         [(o, r) for o in fit.causes for r in rem])
        for c in sw:
            self.assertEqual(c.base_relerr, fit.relerr(w.prep, w.TEST))
            self.assertEqual(set(c.fit.causes), (set(fit.causes) - {c.out}) | {c.cause})
        self.assertEqual([(c.out, c.cause) for c in sw if c.significant], [("asymmetric_friction", "offset")])

    def test_swap_message_and_refits(self):
        w = self.use(World(self.STAND_IN, {"m": 1.0, "a": 0.15, "g": 0.6, "k": 0.4}))
        msgs = []
        d = selection.diagnose(w.prep, msgs.append)
        sw, = d.swapped
        line, = [m for m in msgs if m.startswith("swapped ")]
        self.assertIn(f"held-out relerr {sw['base_relerr_percent']:.3f} % -> {sw['relerr_percent']:.3f} % "
                      f"(gain {100 * sw['relative_gain']:.1f} %, p = {sw['p_value']:.2g}), refitted: "
                      f"{d.extended.relerr(w.prep, w.TEST):.3f} %", line)
        # each swapped model is refitted with the shape (one round) before it is measured
        w.calls.clear()
        fit = w.Fit(("asymmetric_friction", "position_gradient"))
        selection.swaps(w.prep, fit, ["offset"])
        for out in fit.causes:
            new = tuple(c for c in fit.causes if c != out) + ("offset",)
            self.assertIn(("refine", new, 1), w.calls)

    def test_replace_finding(self):
        fs = [(types.SimpleNamespace(cause=c), c.upper()) for c in ("offset", "asymmetric_friction", "position_ripple")]
        new = (types.SimpleNamespace(cause="actuator_delay"), "NEW")
        out = selection.replace_finding(fs, "offset", new)
        # in its place; the others (sorting before or after it) untouched
        self.assertEqual([f[0].cause for f in out], ["actuator_delay", "asymmetric_friction", "position_ripple"])
        self.assertIs(out[0], new)
        self.assertIs(out[1], fs[1])
        self.assertIs(out[2], fs[2])

    def test_a_cause_that_cannot_be_fitted_is_no_swap(self):
        w = self.use(World(self.STAND_IN, {"m": 1.0, "a": 0.15, "g": 0.6, "k": 0.4}))
        add = w.model.add_cause
        w.model.add_cause = lambda prep, base, cause: None if cause == "actuator_delay" else add(prep, base, cause)
        fit = w.Fit(("asymmetric_friction", "position_gradient"))
        sw = selection.swaps(w.prep, fit, ["actuator_delay", "offset", "position_ripple"])
        # the one that cannot be fitted is left out; the others are all still tried
        self.assertEqual([(c.out, c.cause) for c in sw],
                         [(o, r) for o in fit.causes for r in ("offset", "position_ripple")])

    def test_a_swap_that_gains_too_little_is_not_made(self):
        # k no larger than the stand-in's own share a: the swap gains nothing, none is made
        w = self.use(World(self.STAND_IN, {"m": 1.0, "a": 0.15, "g": 0.6, "k": 0.15}))
        d = selection.diagnose(w.prep)
        self.assertEqual(d.swapped, [])
        self.assertEqual({f[0].cause for f in d.findings}, {"asymmetric_friction", "position_gradient"})
        self.assertFalse(any(c.significant for c in selection.swaps(w.prep, d.extended, ["offset"])))


class BorderlineTest(unittest.TestCase):
    def diag(self, rounds, causes_in=("offset",)):
        return selection.Diagnosis(None, [], types.SimpleNamespace(causes=causes_in), rounds)

    @staticmethod
    def row(cause, gain, p, significant=False):
        return {"cause": cause, "relative_gain": gain, "p_value": p, "significant": significant}

    def test_borderline(self):
        g, p = selection.BORDERLINE_GAIN, selection.BORDERLINE_P
        self.assertLess(g, selection.MIN_REL_GAIN)
        self.assertEqual(selection.borderline(self.diag([])), [])
        last = [self.row("offset", 0.5, 1e-6, True),                 # the finding: not listed
                self.row("position_ripple", g, p * 0.999),           # at the edges: listed
                self.row("position_gradient", g * 0.999, 1e-6),      # too small a gain
                self.row("friction_drift", 0.2, p),                  # p not below the level
                self.row("friction_drift", 0.2, 0.3),
                self.row("actuator_delay", 0.3, 0.02, True),         # significant: not borderline
                self.row("asymmetric_friction", 0.04, 0.01)]
        first = [self.row("friction_drift", 0.04, 0.01)]
        b = selection.borderline(self.diag([first, last]))
        self.assertEqual([c["cause"] for c in b], ["position_ripple", "asymmetric_friction"])
        self.assertIs(b[0], last[1])
        # a cause of the model (found, even if not significant this round) is never borderline
        b = selection.borderline(self.diag([last], ("offset", "position_ripple")))
        self.assertEqual([c["cause"] for c in b], ["asymmetric_friction"])
        # only the last round counts
        self.assertEqual(selection.borderline(self.diag([last, [self.row("offset", 0.5, 1e-6, True)]])), [])


if __name__ == "__main__":
    unittest.main()
