"""Parameters of a saved model (model.json "params"): a name (with its unit
in it, the name of the br_plant_cfg_t field it sets), the unit, what it
means, and whether it must be > 0. NOMINAL are the thesis model's, load
side; each cause module (causes/) lists its own in PARAMS. The same names,
units and causes are the C table sim/plant/br_model_params.h (test_model.py
holds the two together); docs/diagnose.md, "Parameters", has the table."""
from typing import NamedTuple


class Param(NamedTuple):
    name: str
    unit: str
    meaning: str
    positive: bool = False  # must be > 0 (else: any finite number)


NOMINAL = (
    Param("Meff_kg", "kg", "moving mass at the load, J/L² + M (a log cannot tell the screw's inertia from the "
          "table's mass; machines/reference.json's M_kg is the table alone)", True),
    Param("sigma2_Nspm", "N s/m", "viscous friction σ2 (moving in +x when the friction is asymmetric)"),
    Param("Fc_N", "N", "Coulomb friction level (moving in +x when the friction is asymmetric)", True),
    Param("Fs_N", "N", "stiction level (the Stribeck curve at rest)", True),
    Param("vs_mps", "m/s", "Stribeck velocity", True),
    Param("sigma0_Npm", "N/m", "bristle stiffness σ0", True),
    Param("sigma1_Nspm", "N s/m", "bristle damping σ1"),
)
