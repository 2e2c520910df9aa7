# SPDX-License-Identifier: Apache-2.0
"""The run-time parameters the link reads and writes by id (param_read,
param_write, param_value; docs/link.md, "Parameters").

Each is an estimator setting the firmware takes per step (the values the
machine file's estimator section gives through est_per_step, and the gates),
on the wire in the unit its name ends in. Their ranges are not here: the
generator (firmware/design/gen_link.py) takes them from the machine file's
schema (firmware/design/machine.py: the per-step bounds for the noises, the
schema's leaf for the gates), so the link refuses what a machine file would.

Fields of a Param:
  id       the u16 on the wire
  name     the firmware's per-step name (est_per_step's key, or the gate's)
  est      "pf", "ukf" or "both": the estimators that have it
  source   where the range comes from: ("per_step", key) for
           machine._PER_STEP_BOUNDS, ("schema", field under estimator.<est>.)
  target   the br_est_cfg_t field it sets (C syntax), and the factor from the
           wire value ("rpc2": times rad_per_count^2, counts^2 to rad^2; "rpc":
           times rad_per_count, counts to rad)
  live     1: written while armed (it is read every period); 0: refused
           while armed, applied at the next arm
"""
from dataclasses import dataclass


@dataclass(frozen=True)
class Param:
    id: int
    name: str
    est: str
    source: tuple
    target: str
    scale: str
    live: int
    doc: str


PARAMS = (
    Param(0x0001, "q_theta_counts2", "pf", ("per_step", "q_theta_counts2"), "q_var[0]", "rpc2", 0,
          "PF: theta's process noise variance per step, counts^2"),
    Param(0x0002, "q_theta_rad2", "ukf", ("per_step", "q_theta_rad2"), "q_var[0]", "", 0,
          "UKF: theta's process noise variance per step, rad^2"),
    Param(0x0003, "q_omega_rad2ps2", "both", ("per_step", "q_omega_rad2ps2"), "q_var[1]", "", 0,
          "omega's process noise variance per step, (rad/s)^2"),
    Param(0x0004, "q_z_m2", "both", ("per_step", "q_z_m2"), "q_var[2]", "", 0,
          "z's process noise variance per step, m^2"),
    Param(0x0005, "q_gp_N2", "both", ("per_step", "q_gp_N2"), "q_var[3]", "", 0,
          "g_p's process noise variance per step, N^2"),
    Param(0x0006, "r_counts2", "both", ("per_step", "r_counts2"), "r_var_rad2", "rpc2", 0,
          "measurement noise variance R, counts^2"),
    Param(0x0007, "outlier_sigma", "both", ("schema", "outlier_gate_sigma"), "outlier_sigma", "", 0,
          "the outlier gate, standard deviations"),
    Param(0x0008, "reanchor_after", "both", ("schema", "reanchor_after"), "reanchor_after", "", 0,
          "consecutive outliers before the filter is re-anchored (an integer)"),
    Param(0x0009, "comp_ahead_periods", "both", ("schema", "comp_ahead_periods"), "comp_ahead_periods", "", 1,
          "the compensation's lead beyond the actuator delay, periods (0: the filtered estimate)"),
    Param(0x000A, "outlier_transient_counts", "both", ("per_step", "outlier_transient_counts"),
          "outlier_transient_rad", "rpc", 0,
          "the outlier gate's transient term d (eq. G1), counts (0: the thesis gate)"),
)

BY_ID = {p.id: p for p in PARAMS}
BY_NAME = {p.name: p for p in PARAMS}
