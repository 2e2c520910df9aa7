# SPDX-License-Identifier: Apache-2.0
"""Testing the causes (causes/), keeping the significant ones, ranking them.

A cause is tested by fitting base + cause on the training part (the shape of
the base held, the cause's own parameters searched) and measuring both models
on the held-out part. It is significant when both hold:

  1. relative gain: the held-out relerr drops by at least MIN_REL_GAIN of the
     base's (a cause worth naming explains a visible share of what is left);
  2. consistency: the held-out part is cut into N_BLOCKS consecutive blocks,
     and the drop of the squared error per block is positive by a one-sided
     Wilcoxon signed-rank test with p-value below P_MAX (blocks, not samples,
     because the residual is strongly correlated in time; ranks, because a
     cause acts unevenly: a gradient at one end of the travel, a delay where
     the acceleration changes).

or when the gain is at least STRONG_GAIN (25 %) with p below P_STRONG (0.05):
a held-out part with dwells has blocks that show no gain either way, and a
gain that large does not come by chance (nominal logs: under 1 %).

Stepwise selection: all causes are tested against the nominal; the one with
the largest held-out gain among the significant ones becomes the first
finding, and the model is refitted with every finding jointly (the shape,
each cause's nonlinear parameters, all linear coefficients). Backward
step: each finding is then tested again by leaving it out of that joint
model (refitted without it); one that no longer gains MIN_REL_GAIN at
p < P_REMOVE there (looser than to enter; an
early finding standing in for causes found after it) is dropped, the
weakest first, and the model refitted, unless the model left would be worse
than the round's starting model: a higher held-out relerr, and not better
in the blocks either (one-sided p < P_REMOVE). Such a drop would trade the
round's starting model for a worse one (an offset swapped for asymmetric
friction, two forces alike while sliding); the joint model stays. The
remaining causes are tested
against the joint model, until none is significant. A dropped cause is not
tested again.

Pairs: two causes can hide each other (an offset with a friction gradient
along the travel: each alone fits the other's force wrongly, gains visibly
but unevenly over the blocks). When no cause is significant alone but one
gains at least MIN_REL_GAIN, each such cause is tested jointly with each
other remaining one (base + both, refitted), by the same gate; the best
significant pair whose members are both needed in it (each kept by the
backward step's level when left out of the pair's model) enters as two
findings, and the backward step tests each as above. On a log at its
noise floor no cause gains MIN_REL_GAIN, and no pair is tested.

Swaps: when nothing can be added, each finding is replaced in turn by each
remaining cause (the model without the finding, refitted, plus the cause,
refitted with the shape) and measured against the current model by the same
significance rule; the best significant swap is made, the cause taking the
finding's place, and the finding is not tested again. Forward selection can
take a stand-in first (asymmetric friction for an offset: the same force
while sliding, by a hair's larger gain) and cannot add the true cause beside
it afterwards (the two are nearly collinear, the joint fit unstable on the
held-out part); the swap replaces it.

The findings are ordered as found, strongest first; every parameter
reported is the final joint model's.
"""
import numpy as np
from scipy import stats

from . import causes as causes_
from . import model

MIN_REL_GAIN = 0.05
REFINE_GAIN = 0.01
REFINE_NFEV = 15
N_BLOCKS = 10
P_MAX = 0.01
# a gain this large needs less consistency over the blocks (a log whose
# held-out part has dwells: their blocks show no gain either way)
STRONG_GAIN = 0.25
P_STRONG = 0.05
# backward step: a finding stays while it gains MIN_REL_GAIN at p < P_REMOVE
# (a looser level than to enter, so that a finding does not flip in and out)
P_REMOVE = 0.05
# borderline: a cause of the last round significant only at this looser level
# (a report lists it as such, never as a finding)
BORDERLINE_GAIN = 0.025
BORDERLINE_P = 0.05


class Candidate:
    """base + cause, measured on the held-out part."""

    def __init__(self, cause, fit, base_relerr, relerr, p_value):
        self.cause, self.fit = cause, fit
        self.base_relerr, self.relerr, self.p_value = base_relerr, relerr, p_value
        self.rel_gain = 1.0 - relerr / base_relerr if base_relerr > 0 else 0.0
        self.significant = ((self.rel_gain >= MIN_REL_GAIN and p_value < P_MAX)
                            or (self.rel_gain >= STRONG_GAIN and p_value < P_STRONG))
        # kept in the joint model (backward step): a looser level than to enter
        self.kept = self.rel_gain >= MIN_REL_GAIN and p_value < P_REMOVE

    def summary(self):
        return {"cause": self.cause, "relerr_percent": self.relerr, "base_relerr_percent": self.base_relerr,
                "relative_gain": self.rel_gain, "p_value": self.p_value, "significant": bool(self.significant),
                "params": self.fit.cause_params(self.cause)}


def block_p_value(prep, e_base, e_new):
    """One-sided p-value that the squared error drops, over N_BLOCKS blocks
    of the held-out part."""
    idx = np.arange(prep.test.start, prep.test.stop)
    d = [float(e_base[b] @ e_base[b] - e_new[b] @ e_new[b]) for b in np.array_split(idx, N_BLOCKS)]
    d = np.asarray(d)
    if np.all(d == 0.0):
        return 1.0
    return float(stats.wilcoxon(d, alternative="greater", zero_method="zsplit").pvalue)


def test(prep, base, cause):
    """base + cause, fitted on the training part, measured on the held-out
    part. The cause's parameters are first searched with the base's LuGre
    shape held; when that already gains REFINE_GAIN, the shape is searched
    again with the cause in (a cause the nominal model could not express
    distorts its shape: a dead time makes the bristles look stiff). Each
    model is measured against its own target (with a dead time, the logged
    force shifted by it), as the report does."""
    fit = model.add_cause(prep, base, cause)
    if fit is None:
        return None
    te = prep.test
    base_rel, e_base = base.relerr(prep, te), base.residual(prep)
    cand = Candidate(cause, fit, base_rel, fit.relerr(prep, te), block_p_value(prep, e_base, fit.residual(prep)))
    if cand.rel_gain >= REFINE_GAIN:
        fit = model.refine(prep, fit, rounds=1, max_nfev=REFINE_NFEV)
        cand = Candidate(cause, fit, base_rel, fit.relerr(prep, te), block_p_value(prep, e_base, fit.residual(prep)))
    return cand


class PairCandidate(Candidate):
    """base + two causes jointly, measured on the held-out part."""

    def __init__(self, pair, fit, base_relerr, relerr, p_value, needed=None):
        super().__init__("+".join(pair), fit, base_relerr, relerr, p_value)
        self.pair = tuple(pair)
        # each member needed in the pair's model (the backward step's level); a pair
        # with a member it does not need is that other cause alone, tested as such
        self.gate = self.significant
        self.needed = dict(needed or {})
        self.significant = self.gate and all(self.needed.get(c, False) for c in self.pair)

    def summary(self):
        return {"causes": list(self.pair), "relerr_percent": self.relerr, "base_relerr_percent": self.base_relerr,
                "relative_gain": self.rel_gain, "p_value": self.p_value, "significant": bool(self.significant),
                "needed": {c: bool(v) for c, v in self.needed.items()},
                "params": {c: self.fit.cause_params(c) for c in self.pair}}

    def member(self, cause):
        """One of the pair as a finding: the pair's fit and measures."""
        return Candidate(cause, self.fit, self.base_relerr, self.relerr, self.p_value)


def test_pair(prep, base, pair):
    """base + both causes of `pair`, each searched in turn with the shape
    held, then refitted with the shape; measured as `test` measures one."""
    fit = base
    for cause in pair:
        fit = model.add_cause(prep, fit, cause)
        if fit is None:
            return None
    fit = model.refine(prep, fit, rounds=1, max_nfev=REFINE_NFEV)
    cand = PairCandidate(pair, fit, base.relerr(prep, prep.test), fit.relerr(prep, prep.test),
                         block_p_value(prep, base.residual(prep), fit.residual(prep)))
    if cand.gate:   # the gate passed: is each member needed? (leave-one-out, as the backward step)
        kept = {b.cause: b.kept for b in backward(prep, fit, pair)}
        cand = PairCandidate(pair, fit, cand.base_relerr, cand.relerr, cand.p_value, kept)
    return cand


def pairs_to_test(cands, remaining):
    """Each cause that gains MIN_REL_GAIN alone (not significantly) with each
    other remaining cause, every pair once, in the order of `remaining`."""
    seeds = {c.cause for c in cands if c.rel_gain >= MIN_REL_GAIN}
    return [(a, b) for i, a in enumerate(remaining) for b in remaining[i + 1:] if a in seeds or b in seeds]


class Diagnosis:
    def __init__(self, nominal, findings, extended, rounds, dropped=(), pairs=(), swapped=()):
        self.nominal = nominal        # Fit
        self.findings = findings      # [(Candidate, Fit after refinement)]
        self.extended = extended      # Fit
        self.rounds = rounds          # [[Candidate summaries]] per selection round
        self.dropped = list(dropped)  # [{cause, round, ...}] found, then dropped by the backward step
        self.pairs = list(pairs)      # [{causes, round, ...}] pairs tested jointly (none alone significant)
        self.swapped = list(swapped)  # [{cause, out, round, ...}] a finding replaced by the cause


def without(prep, fit, cause):
    """The joint model refitted without `cause`."""
    rest = tuple(c for c in fit.causes if c != cause)
    nl = {k: v for k, v in fit.nl.items() if k not in causes_.get(cause).NL}
    base = model.solve(prep, fit.shape, rest, nl)
    return model.refine(prep, base, rounds=1, max_nfev=REFINE_NFEV)


def backward(prep, fit, only=None):
    """Each cause of the joint model (or of `only`) left out in turn:
    Candidates of the cause against the model without it (base = that model)."""
    out = []
    te = prep.test
    for c in (fit.causes if only is None else only):
        base = without(prep, fit, c)
        out.append(Candidate(c, fit, base.relerr(prep, te), fit.relerr(prep, te),
                             block_p_value(prep, base.residual(prep), fit.residual(prep))))
        out[-1].base = base
    return out


def worse_than(prep, left, start):
    """The backward step's guard: `left` (the joint model without a weak
    finding) is worse than `start` (the round's starting model) when its
    held-out relerr is higher and its squared error does not drop from
    start's in the blocks (one-sided p < P_REMOVE): a higher RMS made in one
    block alone does not count (a finding whose gain was one block's)."""
    te = prep.test
    if left.relerr(prep, te) <= start.relerr(prep, te):
        return False
    return block_p_value(prep, start.residual(prep), left.residual(prep)) >= P_REMOVE


def swaps(prep, fit, remaining):
    """Each finding of `fit` replaced by each remaining cause: the model
    without the finding (refitted), the cause added and refitted with the
    shape, measured against `fit` itself. Candidates of the cause coming
    in, with `.out` the finding it replaces."""
    out = []
    te = prep.test
    fit_rel, fit_res = fit.relerr(prep, te), fit.residual(prep)   # what every swap is measured against
    for c in fit.causes:
        rest = without(prep, fit, c)
        for r in remaining:
            f2 = model.add_cause(prep, rest, r)
            if f2 is None:
                continue
            f2 = model.refine(prep, f2, rounds=1, max_nfev=REFINE_NFEV)
            cand = Candidate(r, f2, fit_rel, f2.relerr(prep, te), block_p_value(prep, fit_res, f2.residual(prep)))
            cand.out = c
            out.append(cand)
    return out


def replace_finding(findings, out, new):
    """The findings with `out`'s entry replaced by `new`, in its place."""
    return [new if f[0].cause == out else f for f in findings]


def diagnose(prep, progress=None):
    say = progress or (lambda msg: None)
    nominal = model.fit_nominal(prep)
    say(f"nominal: held-out relerr {nominal.relerr(prep, prep.test):.3f} %")
    base = nominal
    remaining = list(causes_.NAMES)
    findings, rounds, dropped, pairs, swapped = [], [], [], [], []
    # every round that does not end the loop takes one or two causes out of
    # `remaining` (a finding, a pair, a cause swapped in): at most len(NAMES) rounds
    while remaining:
        cands = [c for c in (test(prep, base, cause) for cause in remaining) if c is not None]
        rounds.append([c.summary() for c in cands])
        for c in cands:
            say(f"  {c.cause:20s} held-out relerr {c.relerr:.3f} % (gain {100 * c.rel_gain:.1f} %, "
                f"p = {c.p_value:.2g}){' significant' if c.significant else ''}")
        sig = [c for c in cands if c.significant]
        if not sig:
            # none alone: the pairs of a cause that gains visibly with each other one
            pc = [c for c in (test_pair(prep, base, pr) for pr in pairs_to_test(cands, remaining)) if c is not None]
            for c in pc:
                pairs.append(dict(c.summary(), round=len(rounds)))
                say(f"  {'+'.join(c.pair):40s} held-out relerr {c.relerr:.3f} % (gain {100 * c.rel_gain:.1f} %, "
                    f"p = {c.p_value:.2g}){' significant' if c.significant else ''}")
            sig = [c for c in pc if c.significant]
        if not sig and findings:
            # nothing to add: a finding replaced by a cause not yet in (a stand-in found first)
            sw = [c for c in swaps(prep, base, remaining) if c.significant]
            if not sw:
                break
            best = max(sw, key=lambda c: c.rel_gain)
            start = base
            refined = model.refine(prep, best.fit)
            findings = replace_finding(findings, best.out, (best, refined))
            remaining.remove(best.cause)
            swapped.append(dict(best.summary(), out=best.out, round=len(rounds)))
            say(f"swapped {best.out} for {best.cause}: held-out relerr {best.base_relerr:.3f} % -> "
                f"{best.relerr:.3f} % (gain {100 * best.rel_gain:.1f} %, p = {best.p_value:.2g}), refitted: "
                f"{refined.relerr(prep, prep.test):.3f} %")
        elif not sig:
            break
        else:
            best = max(sig, key=lambda c: c.rel_gain)
            start = base
            refined = model.refine(prep, best.fit)
            members = [best.member(c) for c in best.pair] if isinstance(best, PairCandidate) else [best]
            for m in members:
                findings.append((m, refined))
                remaining.remove(m.cause)
            say(f"finding {len(findings)}: {' and '.join(m.cause for m in members)}, refitted jointly: "
                f"held-out relerr {refined.relerr(prep, prep.test):.3f} %")
        base = refined
        # backward step: a finding that the joint model no longer needs goes
        while len(base.causes) > 1:
            back = backward(prep, base)
            weak = [b for b in back if not b.kept]
            if not weak:
                break
            drop = min(weak, key=lambda b: b.rel_gain)
            if worse_than(prep, drop.base, start):
                say(f"  kept {drop.cause}: without it the held-out relerr {drop.base_relerr:.3f} % would be "
                    f"above the round's start {start.relerr(prep, prep.test):.3f} %")
                break
            say(f"  dropped {drop.cause}: left out of the joint model, held-out relerr {drop.base_relerr:.3f} % "
                f"against {drop.relerr:.3f} % (gain {100 * drop.rel_gain:.1f} %, p = {drop.p_value:.2g})")
            dropped.append(dict(drop.summary(), round=len(rounds)))
            findings = [f for f in findings if f[0].cause != drop.cause]
            base = model.refine(prep, drop.base)
    return Diagnosis(nominal, findings, base, rounds, dropped, pairs, swapped)


def borderline(diag):
    """The last round's causes significant only at the looser level."""
    if not diag.rounds:
        return []
    found = {c for c in diag.extended.causes}
    return [c for c in diag.rounds[-1] if not c["significant"] and c["cause"] not in found
            and c["relative_gain"] >= BORDERLINE_GAIN and c["p_value"] < BORDERLINE_P]
