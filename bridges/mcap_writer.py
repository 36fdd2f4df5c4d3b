"""An MCAP writer whose file is complete (summary and footer) at every checkpoint.

Why not a stock writer: both ``foxglove-sdk``'s and ``mcap``'s writers write the summary
section only when they close, so a log that a World keeps open across ``world.step(n,
log=path)`` calls is not a valid MCAP file between the calls. This writer keeps what a
summary needs (schemas, channels, statistics, chunk and metadata indexes) in memory;
:meth:`CheckpointWriter.checkpoint` writes the current chunk, ``DataEnd``, the summary, the
footer and the closing magic; the next write cuts the file back to where that chunk began
(it stays open in memory and is written again, fuller, later), so the data section simply
continues and frequent checkpoints (``world.step(1, log=path)`` in a loop) still make full
chunks. Between checkpoints every finished
chunk goes straight to the OS, so a killed run leaves a file whose complete chunks the
streaming reader still reads.

Records are serialised by ``mcap.records``; only the bookkeeping lives here.
"""

from __future__ import annotations

import struct
import zlib
from collections import defaultdict
from typing import BinaryIO

from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import (
    Channel,
    Chunk,
    ChunkIndex,
    DataEnd,
    Footer,
    Header,
    Message,
    MessageIndex,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)

MAGIC = b"\x89MCAP0\r\n"


def _compress(codec: str | None, data: bytes) -> bytes:
    if codec == "zstd":
        import zstandard

        return zstandard.ZstdCompressor().compress(data)
    if codec == "lz4":
        import lz4.frame

        return lz4.frame.compress(data)
    return data


class CheckpointWriter:
    """Chunked MCAP writer to an open binary file, valid after every :meth:`checkpoint`.

    Args:
        stream: a seekable binary file opened for writing (unbuffered is best: every finished
            chunk is then in the OS's hands at once).
        compression: ``"zstd"``, ``"lz4"`` or None.
        chunk_size: uncompressed bytes after which a chunk is finished.
        profile, library: the header's fields.
    """

    def __init__(
        self,
        stream: BinaryIO,
        *,
        compression: str | None = "zstd",
        chunk_size: int = 256 * 1024,
        profile: str = "",
        library: str = "abdsim",
    ) -> None:
        if compression not in ("zstd", "lz4", None):
            raise ValueError(f"compression must be 'zstd', 'lz4' or None, got {compression!r}")
        _compress(compression, b"")  # fail now, not at the first chunk, if the codec is missing
        self._stream = stream
        self._codec = compression
        self._chunk_size = int(chunk_size)
        self._schemas: dict[int, Schema] = {}
        self._channels: dict[int, Channel] = {}
        self._chunk_indexes: list[ChunkIndex] = []
        self._metadata_indexes: list[MetadataIndex] = []
        self._counts: dict[int, int] = defaultdict(int)
        self._n_messages = 0
        self._n_metadata = 0
        self._t_min = 0
        self._t_max = 0
        self._pending_defs: list[Schema | Channel] = []
        self._reset_chunk()
        self._data_end: int | None = None  # file offset of DataEnd while a summary is written
        self._open_chunk_offset: int | None = None  # where a checkpointed open chunk starts
        self._closed = False
        stream.write(MAGIC)
        self._write_records([Header(profile=profile, library=library)])

    # -- records ---------------------------------------------------------------------------
    def add_schema(self, name: str, encoding: str, data: bytes) -> int:
        """Register a schema; returns its id."""
        schema = Schema(id=len(self._schemas) + 1, name=name, encoding=encoding, data=data)
        self._schemas[schema.id] = schema
        self._pending_defs.append(schema)
        return schema.id

    def add_channel(
        self, topic: str, message_encoding: str, schema_id: int, metadata: dict | None = None
    ) -> int:
        """Register a channel; returns its id."""
        channel = Channel(
            id=len(self._channels) + 1,
            topic=topic,
            message_encoding=message_encoding,
            schema_id=schema_id,
            metadata=dict(metadata or {}),
        )
        self._channels[channel.id] = channel
        self._pending_defs.append(channel)
        return channel.id

    def add_message(self, channel_id: int, log_time: int, data: bytes) -> None:
        """Append one message to the current chunk (finishing it when it is full)."""
        self._reopen()
        if channel_id not in self._channels:
            raise ValueError(f"unknown channel id {channel_id}")
        # Schemas and channels go into the chunk that first uses them: a reader that
        # recovers a cut file learns each channel before its messages.
        for rec in self._pending_defs:
            rec.write(self._chunk)
        self._pending_defs.clear()
        offset = self._chunk.count
        Message(
            channel_id=channel_id, sequence=0, log_time=log_time, publish_time=log_time, data=data
        ).write(self._chunk)
        self._chunk_index.setdefault(channel_id, []).append((log_time, offset))
        self._chunk_times = (
            log_time if self._chunk_times is None else min(self._chunk_times[0], log_time),
            log_time if self._chunk_times is None else max(self._chunk_times[1], log_time),
        )
        self._t_min = log_time if self._n_messages == 0 else min(self._t_min, log_time)
        self._t_max = log_time if self._n_messages == 0 else max(self._t_max, log_time)
        self._n_messages += 1
        self._counts[channel_id] += 1
        if self._chunk.count >= self._chunk_size:
            self.flush()

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        """Write a metadata record (outside chunks, indexed in the summary)."""
        self._reopen()
        self.flush()
        offset = self._stream.tell()
        record = Metadata(name=name, metadata={str(k): str(v) for k, v in data.items()})
        length = self._write_records([record])
        self._metadata_indexes.append(MetadataIndex(offset=offset, length=length, name=name))
        self._n_metadata += 1

    # -- chunks, checkpoints ---------------------------------------------------------------
    def _reset_chunk(self) -> None:
        self._chunk = RecordBuilder()
        self._chunk_index: dict[int, list[tuple[int, int]]] = {}
        self._chunk_times: tuple[int, int] | None = None

    def flush(self) -> None:
        """Finish the current chunk (with its message indexes) and hand it to the OS."""
        self._reopen()
        self._write_chunk(keep_open=False)

    def _write_chunk(self, keep_open: bool) -> None:
        """Write the current chunk; with ``keep_open`` it stays open for more messages and
        the next write replaces it on disk (so checkpoints do not cut chunks short)."""
        if self._chunk_times is None:
            return
        raw = self._chunk.end()
        data = _compress(self._codec, raw)
        start, end = self._chunk_times
        chunk = Chunk(
            compression=self._codec or "",
            data=data,
            message_start_time=start,
            message_end_time=end,
            uncompressed_crc=zlib.crc32(raw),
            uncompressed_size=len(raw),
        )
        offset = self._stream.tell()
        builder = RecordBuilder()
        chunk.write(builder)
        chunk_length = builder.count
        index_offsets = {}
        for cid, records in self._chunk_index.items():
            index_offsets[cid] = offset + builder.count
            MessageIndex(channel_id=cid, records=records).write(builder)
        self._stream.write(builder.end())
        self._chunk_indexes.append(
            ChunkIndex(
                message_start_time=start,
                message_end_time=end,
                chunk_start_offset=offset,
                chunk_length=chunk_length,
                message_index_offsets=index_offsets,
                message_index_length=self._stream.tell() - offset - chunk_length,
                compression=chunk.compression,
                compressed_size=len(data),
                uncompressed_size=len(raw),
            )
        )
        if keep_open:
            self._chunk.write(raw)  # the builder goes on after the bytes written so far
            self._open_chunk_offset = offset
        else:
            self._reset_chunk()

    def checkpoint(self) -> None:
        """Write the open chunk, DataEnd, summary and footer: the file is complete now.

        Writing more afterwards continues the data section (the open chunk and the summary
        are rewritten at the next checkpoint).
        """
        self._reopen()
        self._write_chunk(keep_open=True)
        self._data_end = self._stream.tell()
        self._write_records([DataEnd(data_section_crc=0)])
        summary_start = self._stream.tell()
        builder = RecordBuilder()
        offsets = []
        stats = Statistics(
            message_count=self._n_messages,
            schema_count=len(self._schemas),
            channel_count=len(self._channels),
            attachment_count=0,
            metadata_count=self._n_metadata,
            chunk_count=len(self._chunk_indexes),
            message_start_time=self._t_min,
            message_end_time=self._t_max,
            channel_message_counts=dict(self._counts),
        )
        groups = [
            (Opcode.SCHEMA, list(self._schemas.values())),
            (Opcode.CHANNEL, list(self._channels.values())),
            (Opcode.STATISTICS, [stats]),
            (Opcode.CHUNK_INDEX, self._chunk_indexes),
            (Opcode.METADATA_INDEX, self._metadata_indexes),
        ]
        for opcode, records in groups:
            if not records:
                continue
            begin = builder.count
            for rec in records:
                rec.write(builder)
            offsets.append(SummaryOffset(opcode, summary_start + begin, builder.count - begin))
        offsets_start = summary_start + builder.count
        for rec in offsets:
            rec.write(builder)
        summary = builder.end()
        # The footer's CRC covers the summary and the footer's own first fields.
        crc = zlib.crc32(
            struct.pack("<BQQQ", Opcode.FOOTER, 20, summary_start, offsets_start),
            zlib.crc32(summary),
        )
        self._stream.write(summary)
        self._write_records(
            [
                Footer(
                    summary_start=summary_start, summary_offset_start=offsets_start, summary_crc=crc
                )
            ]
        )
        self._stream.write(MAGIC)
        self._stream.flush()

    def close(self) -> None:
        """Checkpoint and stop (the stream is left open for its owner to close)."""
        if self._closed:
            return
        self.checkpoint()
        self._closed = True

    def _reopen(self) -> None:
        if self._closed:
            raise ValueError("the MCAP writer is closed")
        if self._data_end is not None:
            cut = self._data_end
            if self._open_chunk_offset is not None:  # the open chunk is rewritten later
                cut = self._open_chunk_offset
                self._chunk_indexes.pop()
                self._open_chunk_offset = None
            self._stream.seek(cut)
            self._stream.truncate()
            self._data_end = None

    def _write_records(self, records: list) -> int:
        builder = RecordBuilder()
        for rec in records:
            rec.write(builder)
        data = builder.end()
        self._stream.write(data)
        return len(data)
