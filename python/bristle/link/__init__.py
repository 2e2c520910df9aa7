# SPDX-License-Identifier: Apache-2.0
"""bristle.link: the host's side of the firmware's link (docs/link.md):
frames (bristle.link.frame) and the message table with its packing
(bristle.link.messages). The serial transport is not here yet."""
from .frame import Decoder, Frame, FrameError, crc16, decode_frame, encode_frame
from .messages import MESSAGES, MessageError, pack, unpack

__all__ = ["Decoder", "Frame", "FrameError", "crc16", "decode_frame", "encode_frame",
           "MESSAGES", "MessageError", "pack", "unpack"]
