# SPDX-License-Identifier: Apache-2.0
"""bristle.link: the host's side of the firmware's link (docs/link.md):
frames (bristle.link.frame) and the message table with its packing
(bristle.link.messages), the recorder's dumps and telemetry as rows and
the measured-log CSV (bristle.link.record); the host tool bristle-link
(bristle.link.cli) with its session over pyserial (bristle.link.session),
trajectories (bristle.link.trajectory) and live plot (bristle.link.liveplot)."""
from .frame import Decoder, Frame, FrameError, crc16, decode_frame, encode_frame
from .messages import MESSAGES, MessageError, pack, unpack
from .record import Capture, DumpError, dump_rows, telemetry_rows, write_measured_log

__all__ = ["Decoder", "Frame", "FrameError", "crc16", "decode_frame", "encode_frame",
           "MESSAGES", "MessageError", "pack", "unpack",
           "Capture", "DumpError", "dump_rows", "telemetry_rows", "write_measured_log"]
