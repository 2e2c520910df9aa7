# SPDX-License-Identifier: Apache-2.0
"""The prediction of the compensation that predicts, float64 golden reference
of firmware/ff/br_ff.c's br_ff_pred_N, written from docs/modules/ff-pred.md:

    dp = v tau + a tau^2 / 2                       (the reference's travel over the horizon)
    g1 = Fc + (Fs - Fc) exp(-|v + a tau| / vs)     (eq. 5 at the horizon's end)
    dF = sum_i k_i clip(z_i + dp, -share_i g1 / k_i, share_i g1 / k_i) - sum_i k_i z_i

The elements are ref.mslip's clamp (numpy's clip), evaluated in float64.
"""
import math

from ref import mslip as rmslip


def level(Fc, Fs, vs, v):
    """eq. 5: g(v) = Fc + (Fs - Fc) exp(-|v| / vs)."""
    return Fc + (Fs - Fc) * math.exp(-abs(v) / vs)


def prediction(p, z, v, a, tau, Fc, Fs, vs):
    """dF for the elements z (array) of the set p (ref.mslip.MslipParams) and
    the reference (v, a) over the horizon tau; also the bound's scale
    S = sum_i k_i (|z_i| + |z1_i| + |dp|) + g1 (docs/golden.md, "ff_pred")."""
    dp = v * tau + 0.5 * a * tau * tau
    g1 = level(Fc, Fs, vs, v + a * tau)
    z1 = rmslip.move(p, z, dp, g1)
    dF = rmslip.force(p, z1, 0.0) - rmslip.force(p, z, 0.0)
    S = sum(k * (abs(zi) + abs(z1i) + abs(dp)) for k, zi, z1i in zip(p.k, z, z1)) + g1
    return dF, S
