# SPDX-License-Identifier: Apache-2.0
"""The noise floor of a log, measured from the log itself (docs/diagnose.md,
"The noise floor").

What no model of the motion can predict is the part of the logged force
that does not follow the motion: measurement noise, the drive's reaction to
the encoder's quantisation. Above the low-pass cutoff the motion of a
ball-screw axis carries almost no force (the moving mass filters it), so
the raw force's content there is that noise. Assuming it is white across
the band, its level there is its level inside the pass band too:

  1. h = F - lp(F): the raw force above the cutoff (lp: the diagnosis's
     zero-phase low-pass);
  2. h cut into SEG-sample segments (Hann window); per segment the mean
     periodogram over the band BAND_LO * fc .. BAND_HI * Nyquist: the
     segment's noise density S (N^2/Hz);
  3. S = the median over the segments (a reversal or a stop, whose force
     step reaches the band, moves only the few segments holding it);
  4. the filtered noise's variance: sigma_f^2 = S * integral of |H(f)|^4
     over 0 .. Nyquist (filtfilt applies the filter H twice);
  5. the floor in relerr terms over the held-out part:
     floor = 100 sigma_f sqrt(n) / ||y||, the relerr a perfect model would
     leave there.

  6. the encoder's share: what the model's prediction does when the path
     it is computed along moves within one position step. The filtered
     position is quantised again with the log's step q (the smallest
     step in the log) at the offsets 0, q/4, q/2, 3q/4, the nominal fit
     predicts the force along each, and the spread of the four
     predictions over the held-out part, as a relerr, is the resolution
     floor (a fine encoder: 0.07 % on the reference machine, 0.003 % on
     EMPS; a 0.1 µm step on the reference axis: about 3 %, where the
     presliding displacement is a few steps long);
  7. the floor: sqrt(noise floor^2 + resolution floor^2).

The log's own white-noise standard deviation sigma = sqrt(S fs / 2) is
reported beside it (it is what br_simlog's --force-noise sets; the
diagnose_model test checks the estimate against logs of known noise).

A residual is "at the floor" when its held-out relerr is at most
AT_FLOOR_FACTOR times the floor, plus AT_FLOOR_ABS_PERCENT (a model fitted on
a finite log never reaches the floor exactly; the margins come from nominal
simulated logs, docs/detection-limits.md gives the false-positive rate they
yield).
"""
import numpy as np
from scipy import signal

SEG = 256
BAND_LO = 2.0        # times the cutoff
BAND_HI = 0.8        # times Nyquist
AT_FLOOR_FACTOR = 1.5
AT_FLOOR_ABS_PERCENT = 0.05


class Floor:
    def __init__(self, sigma_N, sigma_f_N, noise_percent, band_hz, resolution_percent=0.0, step_m=0.0):
        self.sigma_N = sigma_N          # white noise of the raw force, N
        self.sigma_f_N = sigma_f_N      # the same after the diagnosis filter, N
        self.noise_percent = noise_percent    # relerr of that noise over the held-out part
        self.resolution_percent = resolution_percent  # the encoder's share (step 6)
        self.step_m = step_m
        self.percent = float(np.hypot(noise_percent, resolution_percent))
        self.band_hz = band_hz

    def threshold(self):
        """The held-out relerr at or below which a residual is at the floor."""
        return AT_FLOOR_FACTOR * self.percent + AT_FLOOR_ABS_PERCENT

    def at_floor(self, relerr_percent):
        return relerr_percent <= self.threshold()

    def summary(self):
        return {"force_noise_N": self.sigma_N, "filtered_noise_N": self.sigma_f_N,
                "noise_percent": self.noise_percent, "resolution_percent": self.resolution_percent,
                "position_step_m": self.step_m,
                "noise_floor_percent": self.percent, "at_floor_threshold_percent": self.threshold(),
                "band_hz": list(self.band_hz)}


def filter_power_gain(prep, nfreq=4096):
    """Integral of |H(f)|^4 df over 0 .. Nyquist, divided by Nyquist: the
    share of a white noise's variance that passes the zero-phase filter."""
    w, h = signal.freqz(prep._b, prep._a, worN=nfreq)
    return float(np.mean(np.abs(h) ** 4))


RESOLUTION_OFFSETS = (0.0, 0.25, 0.5, 0.75)


def resolution(prep, fit):
    """(relerr of the prediction's spread over sub-step shifts of the path,
    the position step) (step 6)."""
    import copy

    from .machinejson import encoder_step

    q = encoder_step(prep.pos)
    if q <= 0.0 or fit is None:
        return 0.0, q
    preds = []
    for u in RESOLUTION_OFFSETS:
        p = copy.copy(prep)
        p._memo, p._memo_bytes = {}, 0
        p.dx = np.diff(np.floor(prep.xf / q + u) * q)
        preds.append(fit.predict(p)[prep.test])
    var = float(np.var(np.array(preds), axis=0, ddof=1).sum())
    ny = float(np.linalg.norm(prep.y[prep.test]))
    return (100.0 * np.sqrt(var) / ny if ny > 0 else 0.0), q


def measure(prep, fit=None):
    """The Floor of a Prepared log (see the module's doc); the resolution
    floor with the nominal fit `fit`, none without."""
    fs = 1.0 / prep.dt
    nyq = 0.5 * fs
    lo, hi = BAND_LO * prep.fc_hz, BAND_HI * nyq
    h = prep.force - prep.lp(prep.force)
    seg = min(SEG, max(16, len(h) // 8))
    f, t, Z = signal.stft(h, fs=fs, window="hann", nperseg=seg, noverlap=seg // 2, boundary=None, padded=False,
                          detrend=False, scaling="psd")
    band = (f >= lo) & (f <= hi)
    if not band.any() or Z.shape[1] == 0:
        return Floor(0.0, 0.0, 0.0, (lo, hi))
    # scaling="psd" gives |Z|^2 as a one-sided density over 2 (stft's convention)
    per_seg = 2.0 * np.mean(np.abs(Z[band]) ** 2, axis=0)
    S = float(np.median(per_seg))
    sigma = float(np.sqrt(S * nyq))
    sigma_f = sigma * float(np.sqrt(filter_power_gain(prep)))
    te = prep.test
    ny = float(np.linalg.norm(prep.y[te]))
    percent = 100.0 * sigma_f * np.sqrt(te.stop - te.start) / ny if ny > 0 else 0.0
    res, q = resolution(prep, fit)
    return Floor(sigma, sigma_f, float(percent), (lo, hi), res, q)
