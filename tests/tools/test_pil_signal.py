# SPDX-License-Identifier: Apache-2.0
"""The image-in-the-loop tools leave no work folder behind (docs/link.md,
"The image in the loop"): br_pil_tune and br_pil, each run with a stand-in
QEMU (fake_qemu.sh: it records its folder and process id, then never
answers) and stopped by SIGINT, SIGTERM or SIGHUP while they wait for the
image, must remove their /tmp/br_pil_* folders and br_pil_tune its --out
folder's temporary files, end their QEMUs, and end by that signal (the exit
status a killed tool has). The same when the QEMU ends on its own (the
tool's failure path, --timeout 1). Without the signal handling of
sim/lib/pil_loop the signal kills the tool at once and the folders stay.

Usage: test_pil_signal.py --bin DIR --work DIR"""
import os
import signal
import subprocess
import time

import tool_check

FAKE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fake_qemu.sh")


def qemus(log):
    """the (folder, pid) lines the QEMUs wrote"""
    if not os.path.exists(log):
        return []
    with open(log) as f:
        return [ln.split() for ln in f if ln.strip()]


def wait_started(log, proc, wait_s=30.0):
    """1 once both axes' QEMUs have started, 0 when the tool ended first or wait_s passed"""
    end = time.monotonic() + wait_s
    while time.monotonic() < end and proc.poll() is None:
        if len(qemus(log)) >= 2:
            return 1
        time.sleep(0.05)
    return 0


def alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def check(name, cmd, work, sig, fails, out_dir=None):
    """runs cmd with the stand-in QEMU, sends sig (None: lets the QEMU end at once) and checks the clean-up"""
    log = os.path.join(work, name + ".qemus")
    env = dict(os.environ, BR_FAKE_QEMU_LOG=log, BR_FAKE_QEMU_EXIT="0" if sig else "1")
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if sig:
        if not wait_started(log, proc):
            fails.append(f"{name}: the QEMUs did not start")
        time.sleep(0.3)  # the tool now waits for the image's first answer
        proc.send_signal(sig)
    try:
        out, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        fails.append(f"{name}: still running 30 s after the signal")
    print(f"$ {' '.join(cmd)}  ({name})\n{out}{err}", flush=True)
    want = -sig if sig else 1
    if proc.returncode != want:
        fails.append(f"{name}: exit {proc.returncode}, expected {want}")
    rows = qemus(log)
    if len(rows) != 2:
        fails.append(f"{name}: {len(rows)} QEMUs started, expected 2")
    for d, pid in rows:
        if not d.startswith("/tmp/br_pil_"):
            fails.append(f"{name}: work folder {d}, expected one under /tmp/br_pil_")
        if os.path.exists(d):
            fails.append(f"{name}: {d} left behind: {os.listdir(d)}")
        if alive(int(pid)):
            fails.append(f"{name}: QEMU {pid} still running")
            os.kill(int(pid), signal.SIGKILL)
    if out_dir is not None and os.path.isdir(out_dir) and os.listdir(out_dir):
        fails.append(f"{name}: {out_dir} holds {os.listdir(out_dir)}")


def main():
    bindir, work = tool_check.start("bin")
    image = os.path.join(work, "image.elf")  # the stand-in QEMU never reads it
    with open(image, "w") as f:
        f.write("not an image\n")
    fails = []
    qemu = ["--qemu", FAKE, "--image", image]
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        out_dir = os.path.join(work, "out_%s" % sig.name)
        tune = [os.path.join(bindir, "br_pil_tune"), "--out", out_dir, "--timeout", "60"] + qemu
        check("br_pil_tune_" + sig.name, tune, work, sig, fails, out_dir)
        check("br_pil_" + sig.name, [os.path.join(bindir, "br_pil"), "--est", "ukf", "--timeout", "60"] + qemu,
              work, sig, fails)
    # the ordinary failure path: the QEMU ended, no answer within --timeout 1
    tune = [os.path.join(bindir, "br_pil_tune"), "--timeout", "1"] + qemu
    check("br_pil_tune_qemu_ended", tune, work, None, fails)
    return tool_check.finish(fails)


if __name__ == "__main__":
    raise SystemExit(main())
