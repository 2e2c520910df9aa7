# SPDX-License-Identifier: Apache-2.0
"""Golden traces of the plant with the generalized Maxwell-slip friction
(../shared/spec/presliding.md), called by golden/gen_traces.py
(docs/golden.md, "Maxwell-slip plant"):

  plant_gms.csv        the finite-C slip law: four elements of unequal
                       shares and dampings, delta = 1
  plant_gms_clamp.csv  the clamp limit: five elements, breakaways 0.3-30 um,
                       delta = 0.7 (a Stribeck shape other than LuGre's)

Both run the plant traces' duty profile (gen_traces.plant_duties) from rest
with the reference machine's mechanics and Stribeck curve, from
golden/ref/gms.py (float64). The element sets are test choices inside
presliding.md's ranges; the C test reads them from the trace's header.
"""
import numpy as np

from ref import gms as rgms
from ref import plant as rplant

# (name, breakaway displacements at Fs [m], shares, element dampings [N s/m], C [m/s], delta, clamp)
SETS = [
    ("plant_gms", (2e-6, 5e-6, 10e-6, 20e-6), (0.1, 0.2, 0.3, 0.4), (500.0, 1000.0, 2000.0, 3000.0),
     3e-3, 1.0, False),
    ("plant_gms_clamp", (0.3e-6, 1e-6, 3e-6, 10e-6, 30e-6), (0.3, 0.25, 0.2, 0.15, 0.1),
     (1500.0,) * 5, 0.0, 0.7, True),
]


def generate(out_dir, m, gt):
    """Writes the traces; gt is the gen_traces module. Returns the paths."""
    p = rplant.PlantParams.from_machine(m, gt.PLANT_NSUB)
    out = []
    for name, d_m, share, s1, C, delta, clamp in SETS:
        rng = np.random.default_rng(gt.SEED + gt.SEED_OFFSET[name])
        duties = gt.plant_duties(m, rng)
        # d_i = alpha_i Fs / k_i  (presliding.md)
        k = tuple(a * m["Fs_N"] / d for a, d in zip(share, d_m))
        g = rgms.GmsParams(k=k, alpha=share, sigma1=s1, C=C, delta=delta, clamp=clamp)
        pl = rgms.GmsPlant(p, g)
        n = len(k)
        rows = []
        for i, du in enumerate(duties):
            pl.step(du, gt.DT)
            rows.append([i, (i + 1) * gt.DT, du, pl.theta, pl.omega, pl.fnl, pl.encoder_count()] + list(pl.zs))
        meta = gt.plant_meta(m, (0.0, 0.0, 0.0)) + [
            ("gms_n", n), ("gms_clamp", int(clamp)), ("gms_C_mps", C), ("gms_delta", delta),
            ("gms_k_Npm", k), ("gms_alpha", share), ("gms_sigma1_Nspm", s1)]
        cols = ["k", "t", "duty", "theta", "omega", "fnl", "encoder"] + ["z%d" % (i + 1) for i in range(n)]
        out.append(gt.write_trace(out_dir, name, meta, cols, rows, [
            "br_plant_step with the Maxwell-slip friction (%s), from rest, never reset:" %
            ("the clamp limit" if clamp else "the finite-C slip law"),
            "the plant traces' duty profile. State, element deflections and fnl after each step."]))
    return out
