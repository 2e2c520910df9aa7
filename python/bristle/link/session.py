# SPDX-License-Identifier: Apache-2.0
"""A session with a target over a byte port (docs/link.md, "The host tool"):
requests framed with the host's sequence numbers, the reports decoded as
they come, the latest status and ref_status kept, telemetry and dump frames
collected for the caller.

The port is pyserial's (`serial.serial_for_url`: a serial port such as
/dev/ttyACM0, or the simulator's pseudo-terminal, /dev/pts/N, which
br_link_sim prints), opened non-blocking; its input is flushed at the open,
so what a target sent before the session is not taken for a reply.

The session's start (`start`): a hello with a session number of its own;
the target accepts it whatever its last seq, restarts its replay window at
the hello's seq and answers hello_reply (the session number, its protocol
and firmware versions, its machine's name), which `start` waits for and
keeps in `hello`. Within the session a repeated or old frame is still
dropped."""
import os
import time

from . import messages
from .frame import VERSION, Decoder, encode_frame

class LinkError(RuntimeError):
    """A reply that did not come in time, or a refusal."""


def open_port(port, baud):
    """pyserial's port for a path or URL, non-blocking, its input flushed."""
    import serial  # the host tool's dependency (pyproject.toml); only the port needs it
    try:
        ser = serial.serial_for_url(port, baudrate=baud, timeout=0, write_timeout=2.0)
    except (serial.SerialException, ValueError) as e:
        raise LinkError("cannot open %s: %s" % (port, e)) from e
    ser.reset_input_buffer()
    return ser


class Session:
    """One host session on an open port (an object with read(n), write(b),
    in_waiting: pyserial's, or a test's)."""

    def __init__(self, port, start_seq=0):
        self.port = port
        self.dec = Decoder()
        self.seq = start_seq & 0xFFFF
        self.status = None       # the latest status report (dict)
        self.ref_status = None   # the latest ref_status (dict)
        self.tick = None         # the latest period index any report carried
        self.faults = []         # fault reports (dict) in arrival order
        self.param_values = []   # param_value reports
        self.tlm = []            # tlm_sample rows, when collect_tlm
        self.dump = []           # rec_sample / rec_end frames, when collect_dump
        self.collect_tlm = False
        self.collect_dump = False
        self.session = None      # this session's number (start)
        self.hello = None        # its hello_reply (dict)

    def send(self, name, **fields):
        self.port.write(encode_frame(messages.BY_NAME[name].id, self.seq, messages.pack(name, **fields)))
        self.seq = (self.seq + 1) & 0xFFFF

    def start(self, timeout_s=2.0, session=None):
        """Opens the session (above): a hello with a session number (random
        unless given), then waits for its hello_reply (LinkError: the target
        does not answer, or speaks another protocol version); returns it."""
        self.hello = None
        self.session = int.from_bytes(os.urandom(4), "little") if session is None else session & 0xFFFFFFFF
        self.send("hello", session=self.session)
        self.wait("hello_reply from the target", lambda: self.hello is not None, timeout_s)
        if self.hello["version"] != VERSION:
            raise LinkError("the target speaks protocol version %d, this host %d"
                            % (self.hello["version"], VERSION))
        return self.hello

    def _take(self, fr):
        name, v = messages.unpack(fr.id, fr.payload)
        if name in ("status", "ref_status", "tlm_sample"):
            self.tick = v["tick"] if self.tick is None else max(self.tick, v["tick"])
        if name == "status":
            self.status = v
        elif name == "ref_status":
            self.ref_status = v
        elif name == "fault":
            self.faults.append(v)
        elif name == "hello_reply" and v["session"] == self.session:
            self.hello = v
        elif name == "param_value":
            self.param_values.append(v)
        elif name == "tlm_sample" and self.collect_tlm:
            self.tlm.append(v)
        elif name in ("rec_sample", "rec_end") and self.collect_dump:
            self.dump.append(fr)

    def poll(self, wait_s=0.002):
        """Takes what the port holds (waiting at most wait_s for a first
        byte) and decodes it; the number of frames taken."""
        n = self.port.in_waiting
        if not n:
            time.sleep(wait_s)
            n = self.port.in_waiting
        frames = self.dec.feed(self.port.read(n)) if n else []
        for fr in frames:
            self._take(fr)
        return len(frames)

    def wait(self, what, cond, timeout_s):
        """Polls until cond() is true; LinkError naming what after timeout_s."""
        end = time.monotonic() + timeout_s
        while not cond():
            if time.monotonic() > end:
                raise LinkError("no %s within %g s" % (what, timeout_s))
            self.poll()

    def wait_status(self, timeout_s, cond=lambda s: True):
        """A status report that arrives from now on and satisfies cond."""
        self.status = None
        self.wait("status", lambda: self.status is not None and cond(self.status), timeout_s)
        return self.status

    def param(self, pid, value=None, timeout_s=2.0):
        """param_read (value None) or param_write: the param_value answer."""
        self.param_values = []
        if value is None:
            self.send("param_read", param=pid)
        else:
            self.send("param_write", param=pid, value=value)
        self.wait("param_value for %d" % pid, lambda: any(p["param"] == pid for p in self.param_values), timeout_s)
        return next(p for p in self.param_values if p["param"] == pid)
