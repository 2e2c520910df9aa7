# SPDX-License-Identifier: Apache-2.0
"""The live plot of bristle-link (--plot): the telemetry of the run as it
comes, the following error (limited reference - position, m) and the force
commanded (duty through the machine file's amplifier, N) against time, over
the last WINDOW_S seconds; redrawn by a matplotlib animation while the tool
works."""
from .record import machine_scales

WINDOW_S = 5.0


class LivePlot:
    """Two axes over the session's telemetry rows (session.tlm)."""

    def __init__(self, session, machine):
        import matplotlib.pyplot as plt
        self.session = session
        self.sc = machine_scales(machine)
        self.fig, (self.ax_e, self.ax_f) = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
        (self.l_e,) = self.ax_e.plot([], [], lw=1)
        (self.l_f,) = self.ax_f.plot([], [], lw=1)
        self.ax_e.set_ylabel("following error (m)")
        self.ax_f.set_ylabel("force (N)")
        self.ax_f.set_xlabel("t (s)")

    def series(self):
        """(t, following error, force) of the rows within the window"""
        rows = self.session.tlm
        if not rows:
            return [], [], []
        t_end = rows[-1]["tick"] * self.sc["period_s"]
        keep = [r for r in rows[-20000:] if t_end - r["tick"] * self.sc["period_s"] <= WINDOW_S]
        t = [r["tick"] * self.sc["period_s"] for r in keep]
        e = [(r["ref_counts"] + r["ref_frac"] - r["counts"] - 0.5) * self.sc["m_per_count"] for r in keep]
        f = [r["duty"] * self.sc["N_per_duty"] for r in keep]
        return t, e, f

    def update(self, _frame=None):
        t, e, f = self.series()
        self.l_e.set_data(t, e)
        self.l_f.set_data(t, f)
        for ax in (self.ax_e, self.ax_f):
            ax.relim()
            ax.autoscale_view()
        return self.l_e, self.l_f

    def run(self, steps):
        """Drives the tool's work (the generator steps, one poll each) from
        the animation's timer until it ends; the window stays until closed."""
        import matplotlib.pyplot as plt
        from matplotlib.animation import FuncAnimation
        self.anim = FuncAnimation(self.fig, self.update, frames=steps, interval=20, repeat=False,
                                  cache_frame_data=False, blit=False)
        plt.show()
