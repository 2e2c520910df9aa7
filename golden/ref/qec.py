# SPDX-License-Identifier: Apache-2.0
"""Reversal (quadrant-error) compensation pulse, float64 golden reference of
firmware/qec/br_qec.c, written from docs/modules/qec.md:

    s_k = sgn(v_k) (0 at v_k = 0); d = the last non-zero s (0 before any motion)
    reversal at k: s_k != 0 and s_k != d
    A   = max(0, A0 + A1 |a_k|)
    p_k = s_k A at a reversal, else p_{k-1} exp(-dt / tau)

The decay is evaluated as exp(-(k - k_r) dt / tau) from the reversal's step
k_r, not as a running product: the reference has no rounding to carry.
"""
import math


def pulse(v, a, A0, A1, tau, dt):
    """The pulse p_k for the reference velocities v and accelerations a; also
    the steps since the last reversal (-1 before the first) for the tolerance."""
    d, amp, k_r = 0, 0.0, None
    out, since = [], []
    for k, (vk, ak) in enumerate(zip(v, a)):
        s = (vk > 0.0) - (vk < 0.0)
        if s != 0 and s != d:
            amp = s * max(0.0, A0 + A1 * abs(ak))
            d, k_r = s, k
        n = (k - k_r) if k_r is not None else -1
        out.append(amp * math.exp(-n * dt / tau) if k_r is not None else 0.0)
        since.append(n)
    return out, since
