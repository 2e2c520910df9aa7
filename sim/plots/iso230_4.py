#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The circular test as ISO 230-4 reports it, from the demo's traces
(docs/circle-test.md): the circular deviation G about the least-squares
centre, the reversal spikes at each axis reversal the path crosses, and, when
both directions ran (br_demo_circle --dir both), the circular hysteresis H and
the bi-directional circular deviation G(b).

Usage: iso230_4.py DIR
  reads DIR/summary.json and the traces it names, adds "iso230_4" to each
  controller object (only an addition: every other key and value stays as
  br_demo_circle wrote it, byte for byte) and prints the figures as a table.

Definitions (all lengths in m, from the trace's x, y, x_ref, y_ref):
  centre     the least-squares circle of the path: (a, b, R) minimising
             sum (|p_i - (a, b)| - R)^2 over every sample of the trace
  deviation  d_i = |p_i - (a, b)| - R, + outward
  G          max d - min d (ISO 230-4 circular deviation, least-squares centre)
  F          the radial deviation from the nominal radius (the reference's)
             about the same centre: min and max of |p_i - (a, b)| - A
  spikes     at each reversal of an axis's reference (its velocity changes
             sign between two samples, so the run's start and end, where no
             sample lies on one side, are not crossings; its polar angle
             angle_deg to 0.001 deg): travel angle s along
             the path from the reversal (the reference's polar angle, signed
             so that s grows along the path, 0 at the reversal: angle from
             time at the programmed feed, as a ballbar takes it);
             local mean m = mean d over s in [-W, 0), W = 45 deg;
             height h = the d - m of largest magnitude over s in [0, W] (signed,
             + outward; its polar angle peak_angle_deg, its distance from the
             reversal along the path peak_after_deg); width = the s-interval around that peak where
             sign(h) (d - m) >= |h| / 2 (edges interpolated linearly), in deg
             and in s of time
  H          the largest |d_cw(phi) - d_ccw(phi)| at the same polar angle phi
             of the actual points, both about the least-squares centre of the
             two paths together (ISO 230-4 circular hysteresis)
  G(b)       max - min of both paths' deviations about that common centre
             (ISO 230-4 bi-directional circular deviation)
Polar angles: degrees, counter-clockwise from +x (0: +x, 90: +y)."""
import json
import os
import sys

import numpy as np

WINDOW_DEG = 45.0  # W: the arc before a reversal (local mean) and after it (the spike)
CENTRE = "least-squares circle (geometric) of every sample of the trace"


def lsq_circle(x, y):
    """(a, b, R) minimising sum (hypot(x - a, y - b) - R)^2: Gauss-Newton from
    the algebraic fit x^2 + y^2 + D x + E y + F = 0."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    # work about the mean point (small numbers, well conditioned)
    x0, y0 = x.mean(), y.mean()
    u, v = x - x0, y - y0
    A = np.column_stack([u, v, np.ones_like(u)])
    D, E, F = np.linalg.lstsq(A, -(u * u + v * v), rcond=None)[0]
    a, b = -D / 2, -E / 2
    R = np.sqrt(max(a * a + b * b - F, 0.0))
    scale = max(R, np.abs(u).max(), np.abs(v).max(), 1e-300)
    for _ in range(100):
        du, dv = u - a, v - b
        r = np.hypot(du, dv)
        res = r - R
        J = np.column_stack([-du / r, -dv / r, -np.ones_like(r)])
        step = np.linalg.lstsq(J, -res, rcond=None)[0]
        a, b, R = a + step[0], b + step[1], R + step[2]
        if np.abs(step).max() <= 1e-15 * scale:
            break
    return a + x0, b + y0, R


def deviation(x, y, centre, R):
    return np.hypot(np.asarray(x) - centre[0], np.asarray(y) - centre[1]) - R


def travel_angle(x_ref, y_ref):
    """the reference's polar angle, unwrapped and signed to grow along the
    path, deg; and the sign (+1 counter-clockwise, -1 clockwise)"""
    th = np.degrees(np.unwrap(np.arctan2(y_ref, x_ref)))
    sgn = 1.0 if th[-1] >= th[0] else -1.0
    return sgn * th, sgn


def reversals(t, x_ref, y_ref):
    """each sign change of an axis's reference velocity with samples on both
    sides: (axis, t_r, polar angle of the reversal in deg, travel angle s_r)"""
    s, sgn = travel_angle(x_ref, y_ref)
    out = []
    for axis, q in (("x", np.asarray(x_ref)), ("y", np.asarray(y_ref))):
        dq = np.diff(q)
        for k in range(1, len(dq)):
            if (dq[k - 1] > 0) != (dq[k] > 0) and dq[k - 1] != 0 and (dq[k] != 0 or k + 1 < len(dq)):
                # the velocity's zero between the midpoints k - 1/2 and k + 1/2
                frac = dq[k - 1] / (dq[k - 1] - dq[k])
                pos = k - 0.5 + frac
                t_r = float(np.interp(pos, np.arange(len(t)), t))
                s_r = float(np.interp(pos, np.arange(len(s)), s))
                out.append((axis, t_r, float(np.mod(np.round(sgn * s_r, 3), 360.0)), s_r))
    return sorted(out, key=lambda r: r[1])


def _edge(s, f, i, j, half):
    """the s where f crosses half between samples i (f >= half) and j (f < half)"""
    return s[i] + (half - f[i]) / (f[j] - f[i]) * (s[j] - s[i])


def spike(t, s, d, s_r, window_deg=WINDOW_DEG):
    """the reversal spike at travel angle s_r (definitions: the module's doc),
    or None when the trace does not hold the whole window around it"""
    if s_r - window_deg < s[0] or s_r + window_deg > s[-1]:
        return None
    before = (s >= s_r - window_deg) & (s < s_r)
    win = np.flatnonzero((s >= s_r - window_deg) & (s <= s_r + window_deg))
    m = float(np.mean(d[before]))
    after = win[s[win] >= s_r]
    k = after[np.argmax(np.abs(d[after] - m))]
    h = float(d[k] - m)
    f = np.sign(h) * (d - m)
    half = abs(h) / 2
    lo, hi = win[0], win[-1]
    i = k
    while i > lo and f[i - 1] >= half:
        i -= 1
    j = k
    while j < hi and f[j + 1] >= half:
        j += 1
    clipped = (i == lo and f[i] >= half) or (j == hi and f[j] >= half)
    s_left = _edge(s, f, i, i - 1, half) if i > lo else s[i]
    s_right = _edge(s, f, j, j + 1, half) if j < hi else s[j]
    t_left = float(np.interp(s_left, s, t))
    t_right = float(np.interp(s_right, s, t))
    return {"height_m": h, "local_mean_m": m, "peak_after_deg": float(s[k] - s_r), "width_deg": float(s_right - s_left),
            "width_s": t_right - t_left, "width_clipped": bool(clipped)}


def analyse(t, x_ref, y_ref, x, y, window_deg=WINDOW_DEG):
    """the figures of one run: G, F, the centre, the spikes (the module's doc)"""
    t = np.asarray(t, float)
    a, b, R = lsq_circle(x, y)
    d = deviation(x, y, (a, b), R)
    A = float(np.mean(np.hypot(x_ref, y_ref)))  # the nominal radius
    F = np.hypot(np.asarray(x) - a, np.asarray(y) - b) - A
    s, sgn = travel_angle(x_ref, y_ref)
    spikes = []
    for axis, t_r, ang, s_r in reversals(t, x_ref, y_ref):
        sp = spike(t, s, d, s_r, window_deg)
        if sp is not None:
            peak = float(np.mod(np.round(sgn * (s_r + sp["peak_after_deg"]), 6), 360.0))
            spikes.append({"axis": axis, "angle_deg": ang, "t_s": t_r, **sp, "peak_angle_deg": peak})
    return {"centre": CENTRE, "centre_m": [float(a), float(b)], "lsq_radius_m": float(R),
            "circular_deviation_m": float(d.max() - d.min()),
            "radial_deviation_m": {"min": float(F.min()), "max": float(F.max())},
            "window_deg": window_deg, "reversal_spikes": spikes}


def bidirectional(cw, ccw, step_deg=0.1):
    """H and G(b) of two paths, each (x, y) (the module's doc)"""
    x = np.concatenate([cw[0], ccw[0]])
    y = np.concatenate([cw[1], ccw[1]])
    a, b, R = lsq_circle(x, y)
    grid = np.arange(0.0, 360.0, step_deg)
    ds, dev = [], []
    for px, py in (cw, ccw):
        d = deviation(px, py, (a, b), R)
        phi = np.degrees(np.mod(np.arctan2(np.asarray(py) - b, np.asarray(px) - a), 2 * np.pi))
        order = np.argsort(phi)
        ds.append(np.interp(grid, phi[order], d[order], period=360.0))
        dev.append(d)
    allv = np.concatenate(dev)
    return {"centre": "least-squares circle (geometric) of both paths' samples together",
            "centre_m": [float(a), float(b)], "circular_hysteresis_m": float(np.max(np.abs(ds[0] - ds[1]))),
            "bidirectional_circular_deviation_m": float(allv.max() - allv.min())}


def load_trace(path):
    return np.genfromtxt(path, delimiter=",", names=True)


def analyse_trace(tr, window_deg=WINDOW_DEG):
    return analyse(tr["t"], tr["x_ref"], tr["y_ref"], tr["x"], tr["y"], window_deg)


# the controller objects of summary.json: (section path, name, object)
CONTROLLERS = ("hinf_only", "hinf_ukf", "hinf_pf", "hinf_true", "hinf_ff")


def sections(s):
    """(plant label, direction, its controllers' objects, the ccw counterpart section or None)"""
    main_dir = s.get("experiment", {}).get("direction", "cw")
    out = []
    for plant, sec in (("reference", s), ("realistic", s.get("realistic"))):
        if not sec:
            continue
        out.append((plant, main_dir, sec, sec.get("ccw")))
        if sec.get("ccw"):
            out.append((plant, "ccw", sec["ccw"], None))
    return out


def compute(d, s):
    """{trace file: iso230_4 object} for every controller of summary s in folder d"""
    res, traces = {}, {}
    for _plant, _dr, sec, _pair in sections(s):
        for n in CONTROLLERS:
            if n in sec:
                f = sec[n]["trace"]
                traces[f] = load_trace(os.path.join(d, f))
                res[f] = analyse_trace(traces[f])
    for _plant, _dr, sec, pair in sections(s):
        if not pair:
            continue
        for n in CONTROLLERS:
            if n in sec and n in pair:
                a, b = traces[sec[n]["trace"]], traces[pair[n]["trace"]]
                bi = bidirectional((a["x"], a["y"]), (b["x"], b["y"]))
                res[sec[n]["trace"]]["bidirectional"] = {"pair_trace": pair[n]["trace"], **bi}
    return res


def _strip(o):
    if isinstance(o, dict):
        return {k: _strip(v) for k, v in o.items() if k != "iso230_4"}
    return o


def insert(text, res):
    """summary.json's text with "iso230_4" added as the last key of each
    controller object (one line each, as br_demo_circle writes them); a former
    insertion is replaced. Every other byte stays."""
    lines = text.split("\n")
    for f, iso in res.items():
        key = '"trace": "%s"' % f
        hits = [i for i, ln in enumerate(lines) if key in ln]
        if len(hits) != 1:
            raise ValueError("summary.json: %d controller lines name %s" % (len(hits), f))
        ln = lines[hits[0]]
        head = ln[:ln.index(key) + len(key)]
        tail = "," if ln.endswith(",") else ""
        lines[hits[0]] = head + ', "iso230_4": ' + json.dumps(iso) + "}" + tail
    new = "\n".join(lines)
    if _strip(json.loads(new)) != _strip(json.loads(text)):
        raise ValueError("summary.json: the insertion changed another value")
    return new


def table(s, res):
    """the printed table"""
    lab = {"hinf_only": "H-inf only", "hinf_ukf": "H-inf + UKF", "hinf_pf": "H-inf + PF",
           "hinf_true": "true friction", "hinf_ff": "H-inf + FF"}
    out = ["ISO 230-4 circular test (docs/circle-test.md): G = max - min radial deviation about the least-squares "
           "centre;", "reversal spikes: axis@angle, height above the mean of the %g deg before the reversal, "
           "width at half height" % WINDOW_DEG]
    for plant, dr, sec, pair in sections(s):
        out.append("%s plant, %s:" % (plant, {"cw": "clockwise", "ccw": "counter-clockwise"}[dr]))
        out.append("%-14s %11s  %s" % ("controller", "G [m]", "spikes: axis@angle height [m] / width [deg]"))
        for n in CONTROLLERS:
            if n not in sec:
                continue
            r = res[sec[n]["trace"]]
            sp = "  ".join("%s@%g: %+.2e / %.1f%s" % (p["axis"], round(p["angle_deg"], 1), p["height_m"],
                                                      p["width_deg"], "+" if p["width_clipped"] else "")
                           for p in r["reversal_spikes"])
            out.append("%-14s %11.3e  %s" % (lab[n], r["circular_deviation_m"], sp))
        if pair:
            out.append("%-14s %14s %14s" % ("cw / ccw pair", "H [m]", "G(b) [m]"))
            for n in CONTROLLERS:
                if n in sec and "bidirectional" in res[sec[n]["trace"]]:
                    bi = res[sec[n]["trace"]]["bidirectional"]
                    out.append("%-14s %14.3e %14.3e" % (lab[n], bi["circular_hysteresis_m"],
                                                         bi["bidirectional_circular_deviation_m"]))
    out.append("(a width marked + reaches the window's edge: at least that wide)")
    if not any(pair for _p, _d, _s, pair in sections(s)):
        out.append("the clockwise / counter-clockwise pair (hysteresis H, bi-directional G(b)): "
                   "br_demo_circle --dir both (make demo DIR=both)")
    return "\n".join(out)


def main(d):
    p = os.path.join(d, "summary.json")
    with open(p) as f:
        text = f.read()
    s = json.loads(text)
    res = compute(d, s)
    new = insert(text, res)
    tmp = p + ".iso-tmp"
    with open(tmp, "w") as f:
        f.write(new)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, p)
    print(table(s, res))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
