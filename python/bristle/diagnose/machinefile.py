# SPDX-License-Identifier: Apache-2.0
"""The machine file of a log (docs/diagnose.md, "Machine file"): which one,
and its checked reading. Every field the diagnosis uses is checked before
the fit, with "file:line: problem":

  name, source     strings
  logs             a list of log file names (how a file of machines/ is found)
  controller       closedloop.CONTROLLER's keys within their bounds
  published        {"models": [{"name", "relerr_percent", ...}], "closed_loop": {...}}"""
import os

from . import closedloop, jsonfile
from .logreader import LogError
from .params import Param

MACHINES_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "machines")
RELERR = Param("relerr_percent", "%", "a published relative error", 0.0, 1e6)
CLOSED_LOOP_KEYS = ("relerr_position_percent", "relerr_velocity_percent", "relerr_acceleration_percent",
                    "relerr_force_percent")


def known(log):
    """A machine file of machines/ that lists the log's file name."""
    name = os.path.basename(log)
    for f in sorted(os.listdir(MACHINES_DIR)):
        p = os.path.join(MACHINES_DIR, f)
        try:
            m, _ = jsonfile.load(p)
        except LogError:
            continue
        if isinstance(m, dict) and isinstance(m.get("logs"), list) and name in m["logs"]:
            return p
    return None


def find(log, given=None):
    """given, else <log>.machine.json beside the log, else one of machines/
    listing the log's name; None when there is none."""
    if given is not None:
        return given
    side = os.path.splitext(log)[0] + ".machine.json"
    return side if os.path.exists(side) else known(log)


def _published(pub, path, text):
    where = path, jsonfile.line_of(text, "published")
    if not isinstance(pub, dict):
        raise LogError(*where, "\"published\" must be an object")
    models = pub.get("models", [])
    if not isinstance(models, list):
        raise LogError(*where, "\"published\": \"models\" must be a list")
    for m in models:
        if not isinstance(m, dict) or not isinstance(m.get("name"), str):
            raise LogError(*where, "\"published\": each model needs a \"name\" string")
        problem = RELERR.check(m.get("relerr_percent"))
        if problem:
            raise LogError(path, jsonfile.line_of(text, m["name"]), f"\"published\" model {jsonfile.describe(m['name'])}: "
                           + problem)
    cl = pub.get("closed_loop")
    if cl is not None:
        where = path, jsonfile.line_of(text, "closed_loop")
        if not isinstance(cl, dict) or not isinstance(cl.get("model"), str):
            raise LogError(*where, "\"published\": \"closed_loop\" needs a \"model\" string")
        for k in CLOSED_LOOP_KEYS:
            problem = RELERR._replace(name=k).check(cl.get(k))
            if problem:
                raise LogError(*where, f"\"published\": \"closed_loop\": {problem}")


def load(path):
    """The machine file, checked: (dict, controller or None). LogError or
    closedloop.ControllerError "file:line: problem" when it cannot be used."""
    m, text = jsonfile.load(path)
    if not isinstance(m, dict):
        raise LogError(path, 1, "a JSON object was expected")
    for k in ("name", "source"):
        if k in m and not isinstance(m[k], str):
            raise LogError(path, jsonfile.line_of(text, k), f"\"{k}\" must be a string")
    if "logs" in m and not (isinstance(m["logs"], list) and all(isinstance(x, str) for x in m["logs"])):
        raise LogError(path, jsonfile.line_of(text, "logs"), "\"logs\" must be a list of file names")
    if "published" in m:
        _published(m["published"], path, text)
    ctrl = None
    if "controller" in m:
        ctrl = closedloop.check_controller(m["controller"], f"{path}:{jsonfile.line_of(text, 'controller')}")
    return m, ctrl
