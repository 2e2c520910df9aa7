# SPDX-License-Identifier: Apache-2.0
"""The link's message set: the one table both sides take their ids and
payload layouts from (docs/link.md, "Messages").

The C side reads it through the generated header
firmware/gen/bristle_gen/link/br_link_msgs.h (firmware/design/gen_link.py,
checked by the regen test regen_link_msgs); the Python side reads it here at
run time, which is why the table lives in Python: an installed bristle.link
has no C header to read.

A payload is its fields in order, packed, little-endian, without padding.
Field types: u8, i8, u16, u32, i32, f32 (IEEE 754 binary32), c16 (16 bytes
of ASCII text, NUL-padded; a bytes value)."""
import struct
from dataclasses import dataclass

# who sends a message: the target (the firmware) or the host (bristle.link)
TO_HOST = "to_host"
TO_TARGET = "to_target"

# struct codes of the field types (little-endian, "<" in pack/unpack)
TYPES = {"u8": "B", "i8": "b", "u16": "H", "u32": "I", "i32": "i", "f32": "f", "c16": "16s"}


@dataclass(frozen=True)
class Field:
    name: str
    type: str
    doc: str


@dataclass(frozen=True)
class Message:
    name: str
    id: int
    direction: str
    fields: tuple
    doc: str

    @property
    def fmt(self):
        """the payload's struct format"""
        return "<" + "".join(TYPES[f.type] for f in self.fields)

    @property
    def size(self):
        """the payload's length in bytes (the only length accepted)"""
        return struct.calcsize(self.fmt)

    def offsets(self):
        """(field, byte offset) in payload order"""
        out, off = [], 0
        for f in self.fields:
            out.append((f, off))
            off += struct.calcsize("<" + TYPES[f.type])
        return out


# One control period's sample (firmware/rec/br_rec_sample.c): the payload of
# tlm_sample, and of rec_sample after its index.
SAMPLE_FIELDS = (
    Field("tick", "u32", "the control period's index (the caller's)"),
    Field("counts", "i32", "the encoder count the period used"),
    Field("ref_counts", "i32", "the limited reference the controller tracked: whole counts ..."),
    Field("ref_frac", "f32", "... and the fraction of a count, in [0, 1)"),
    Field("duty", "f32", "PWM duty written, [-1, 1]"),
    Field("F_hat_N", "f32", "the compensation force used (N, load side)"),
    Field("n_outliers", "u16", "outlier periods in the lock monitor's window"),
    Field("status", "i8", "br_app_step's status (1 BR_W_OUTLIER: the measurement was skipped)"),
    Field("fault", "u8", "br_app_fault_t (0 none, 1 disarmed)"),
    Field("flags", "u8", "bit 0 reference limited, 1 torque saturated, 2 encoder read held, 3-4 br_app_stop_t"),
)

MESSAGES = (
    Message("status", 0x01, TO_HOST, (
        Field("tick", "u32", "control period index of the report"),
        Field("fault_tick", "u32", "period index at which the fault latched (0 without a fault)"),
        Field("armed", "u8", "1 armed, 0 disarmed"),
        Field("fault", "u8", "the latched cause (br_app_fault_t; 0 none)"),
    ), "the application's state, sent periodically or on a state change"),
    Message("fault", 0x02, TO_HOST, (
        Field("cause", "u8", "the latched cause (br_app_fault_t)"),
        Field("tick", "u32", "period index at which it latched"),
    ), "a fault latched: sent once, when it happens"),
    # the session (docs/link.md, "The session"): 0x08-0x0F
    Message("hello", 0x08, TO_TARGET, (
        Field("session", "u32", "the host's session number (any value but the session in force)"),
    ), "opens a session: the target accepts it with any seq, restarts its replay window there, and answers hello_reply"),
    Message("hello_reply", 0x09, TO_HOST, (
        Field("session", "u32", "the hello's session number"),
        Field("version", "u8", "the protocol version the target speaks (BR_LINK_VERSION)"),
        Field("fw_version", "u32", "the firmware's version (major << 16 | minor << 8 | patch, bristle/br_version.h)"),
        Field("machine", "c16", "the machine file's name the image was built for (first 16 bytes, NUL-padded)"),
    ), "the answer to hello"),
    Message("arm", 0x10, TO_TARGET, (), "arm request: outputs on, control runs"),
    Message("disarm", 0x11, TO_TARGET, (), "disarm request: duty 0, outputs off"),
    Message("fault_reset", 0x12, TO_TARGET, (), "clear a latched fault (the axis stays disarmed)"),
    Message("param_read", 0x20, TO_TARGET, (
        Field("param", "u16", "parameter id"),
    ), "read one run-time parameter; answered by param_value"),
    Message("param_write", 0x21, TO_TARGET, (
        Field("param", "u16", "parameter id"),
        Field("value", "f32", "the new value, in the parameter's unit"),
    ), "write one run-time parameter (finite, range-checked by the target's hook); answered by param_value"),
    Message("param_value", 0x22, TO_HOST, (
        Field("param", "u16", "parameter id"),
        Field("value", "f32", "the value now in force (a refused write: the value asked for)"),
        Field("status", "i8", "br_status_t of the read or write (0 BR_OK; negative: refused)"),
    ), "the answer to param_read and param_write"),
    # the reference source (docs/link.md, "Setpoints and segments"); 0x40-0x5F are telemetry's
    Message("setpoint", 0x30, TO_TARGET, (
        Field("tick", "u32", "the control period it is the reference of"),
        Field("counts", "i32", "reference position, whole encoder counts"),
        Field("frac", "f32", "its fraction of a count, [0, 1)"),
        Field("omega_radps", "f32", "reference velocity, motor side, rad/s"),
        Field("flags", "u8", "bit 0: the stream's last item (then hold, no underrun)"),
    ), "one timed setpoint into the reference queue (br_refq)"),
    Message("segment", 0x31, TO_TARGET, (
        Field("tick", "u32", "the control period it starts at"),
        Field("periods", "u32", "its duration in control periods, >= 1"),
        Field("counts", "i32", "start position, whole encoder counts"),
        Field("frac", "f32", "its fraction of a count, [0, 1)"),
        Field("v_cps", "f32", "start velocity, counts/s"),
        Field("a_cps2", "f32", "start acceleration, counts/s^2"),
        Field("j_cps3", "f32", "jerk, counts/s^3 (0: a constant-acceleration segment)"),
        Field("flags", "u8", "bit 0: the stream's last item (then hold, no underrun)"),
    ), "a cubic trajectory segment the target interpolates, one reference per period"),
    Message("ref_status", 0x32, TO_HOST, (
        Field("tick", "u32", "control period index of the report"),
        Field("queued", "u8", "items in the reference queue"),
        Field("free", "u8", "free places in it"),
        Field("state", "u8", "br_refq_state_t: 0 idle, 1 streaming, 2 underrun hold, 3 underrun braking, 4 underrun fault"),
        Field("dropped", "u32", "items refused: queue full (counted, not queued)"),
        Field("late", "u32", "items refused or dropped: out of order, or over before their time came"),
        Field("underruns", "u32", "underruns begun"),
    ), "the reference queue's state, sent with each periodic status"),
    # telemetry and the recorder: ids 0x40-0x5F (docs/link.md, "Telemetry", "The recorder")
    Message("tlm_sample", 0x40, TO_HOST, SAMPLE_FIELDS,
            "telemetry: one control period's sample, every N periods (br_tlm)"),
    Message("rec_sample", 0x41, TO_HOST, (
        Field("index", "u16", "the sample's place in the capture, 0 the oldest"),
    ) + SAMPLE_FIELDS, "a recorder dump's chunk: one sample of the capture (br_rec)"),
    Message("rec_end", 0x42, TO_HOST, (
        Field("count", "u16", "samples in the capture (0: no capture complete, see state)"),
        Field("trigger_index", "u16", "the trigger sample's index (the samples before it are the pre-trigger ones)"),
        Field("trigger_tick", "u32", "the trigger sample's tick"),
        Field("cause", "u8", "what triggered (br_rec_trig_t: 1 fault, 2 command, 3 condition; 0 none)"),
        Field("state", "u8", "the recorder's state (br_rec_state_t: 0 armed, 1 collecting, 2 done)"),
        Field("missed_faults", "u16", "faults that latched while a capture was held (not captured)"),
    ), "the end of a dump (after its last rec_sample), or the answer to a dump before a capture is complete"),
    Message("rec_arm", 0x50, TO_TARGET, (),
            "recorder: drop the capture, record again and wait for a trigger"),
    Message("rec_trigger", 0x51, TO_TARGET, (),
            "recorder: the next sample recorded is the trigger (when armed)"),
    Message("rec_dump", 0x52, TO_TARGET, (
        Field("first", "u16", "the first index to send (0: the whole capture)"),
    ), "recorder: send the capture from index first, then rec_end"),
    # the image in the loop (docs/link.md, "The image in the loop"): ids 0x60-0x6F, on
    # the emulated board's plant port (a UART of its own), never on the link
    Message("pil_tick", 0x60, TO_TARGET, (
        Field("tick", "u32", "the host's period index"),
        Field("counts", "i32", "the encoder count of the period (the host plant's)"),
        Field("link_bytes", "u32", "bytes the host has written on the link since the start, modulo 2^32"),
    ), "image in the loop: one control period's tick and encoder count; the period runs once the link's bytes are in"),
    Message("pil_out", 0x61, TO_HOST, (
        Field("port_duty", "f32", "the duty the PWM port holds after the period, [-1, 1]: what the amplifier gets"),
        Field("on", "u8", "1 the outputs are on, 0 off"),
    ) + SAMPLE_FIELDS, "image in the loop: the period's output and its sample (tick: the pil_tick's)"),
)

BY_ID = {m.id: m for m in MESSAGES}
BY_NAME = {m.name: m for m in MESSAGES}


def check_table(messages=MESSAGES):
    """Raises ValueError on a table that cannot be generated: a repeated id or
    name, an id outside 1..255 or a payload above the frame's maximum."""
    from .frame import PAYLOAD_MAX
    ids, names = set(), set()
    for m in messages:
        if not 1 <= m.id <= 255 or m.id in ids:
            raise ValueError("message %s: id 0x%02x out of range or repeated" % (m.name, m.id))
        if m.name in names or not m.name.isidentifier():
            raise ValueError("message name %r repeated or not an identifier" % m.name)
        if m.direction not in (TO_HOST, TO_TARGET) or m.size > PAYLOAD_MAX:
            raise ValueError("message %s: bad direction or payload above %d bytes" % (m.name, PAYLOAD_MAX))
        for f in m.fields:
            if f.type not in TYPES:
                raise ValueError("message %s field %s: unknown type %s" % (m.name, f.name, f.type))
        ids.add(m.id)
        names.add(m.name)


class MessageError(ValueError):
    """A frame's id is not in the table, or its payload has the wrong length."""


def pack(name, **values):
    """The payload of message `name` from its field values (every field, by name)."""
    m = BY_NAME[name]
    want = [f.name for f in m.fields]
    if sorted(values) != sorted(want):
        raise MessageError("message %s takes the fields %s, got %s" % (name, want, sorted(values)))
    return struct.pack(m.fmt, *(values[k] for k in want))


def unpack(msg_id, payload):
    """(name, {field: value}) of a payload; MessageError for an unknown id or a wrong length."""
    m = BY_ID.get(msg_id)
    if m is None:
        raise MessageError("unknown message id 0x%02x" % msg_id)
    if len(payload) != m.size:
        raise MessageError("message %s: payload of %d bytes, expected %d" % (m.name, len(payload), m.size))
    return m.name, dict(zip((f.name for f in m.fields), struct.unpack(m.fmt, bytes(payload))))
