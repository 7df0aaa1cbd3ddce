"""MCAP record framing shared by the fast writer (:mod:`._container`) and the tolerant scanner
(:mod:`._scan`): the file magic and the record opcodes of the MCAP specification
(:class:`mcap.opcode.Opcode`). Every record is ``opcode u8, length u64, body``.
"""

from __future__ import annotations

_MAGIC = b"\x89MCAP0\r\n"
# Record opcodes of the MCAP specification (mcap.opcode.Opcode).
_OP_FOOTER, _OP_SCHEMA, _OP_CHANNEL, _OP_MESSAGE, _OP_CHUNK = 0x02, 0x03, 0x04, 0x05, 0x06
_OP_MESSAGE_INDEX, _OP_ATTACHMENT, _OP_METADATA, _OP_DATA_END = 0x07, 0x09, 0x0C, 0x0F
