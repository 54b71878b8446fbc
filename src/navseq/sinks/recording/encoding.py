"""One MCAP file of ROS messages, in ROS 2 (CDR) or ROS 1 encoding, behind one interface.

:class:`McapRecording` takes messages as plain nested dicts with ROS 2's field names
(:mod:`navseq.sinks.recording.messages` builds them) and has the ``mcap`` libraries
encode them: ``mcap_ros2``'s CDR encoder, or the ROS 1 message classes that
``mcap_ros1``'s bundled genpy generates from the definition (no ROS needed for either).
Nothing here serialises by hand. The few fields ROS 1 names differently are the
ROS 1 encoder's business (:func:`_fill_ros1`): a dict key the type lacks is left out,
a field the dict lacks keeps its default.

The file is chunked: messages gather in a chunk that is compressed and written once it
holds :data:`CHUNK_SIZE` bytes, or when :meth:`McapRecording.flush` is called (the sink
does each second of wall time and at every waypoint's end). A process killed mid-run
leaves a file whose complete chunks all read back; only the open chunk is lost.
"""

from __future__ import annotations

import io
from collections.abc import Callable, Mapping
from typing import IO, Any, Literal

from navseq import __version__
from navseq.sinks.recording.definitions import message_definition

RecordingFormat = Literal["ros2", "ros1"]
#: The encodings ``--record-format`` offers; the first is the default.
FORMATS: tuple[RecordingFormat, ...] = ("ros2", "ros1")
#: Bytes of messages (before compression) per chunk before it is written. The
#: example tour (68.6 s, 1450 messages) fills 23 chunks, one per ~3 s of the run: a
#: crash loses little, and zstd still finds the repeats (covariances, frame names) it
#: compresses (138 kB for the tour, its 147 kB map included).
CHUNK_SIZE = 32 * 1024
LIBRARY = f"navseq {__version__}"

Encoder = Callable[[Mapping[str, Any]], bytes]


class McapRecording:
    """An MCAP file being written: register nothing, just :meth:`write` messages.

    Schemas and channels are registered the first time a type or topic is written.
    ``stream`` is a binary file opened for writing; :meth:`finish` writes the summary
    (the index a seeking reader uses) and closes it.
    """

    def __init__(self, stream: IO[bytes], record_format: RecordingFormat) -> None:
        from mcap.writer import CompressionType, Writer

        self._stream = stream
        self._format = record_format
        self._encoding: _Ros2 | _Ros1 = _Ros2() if record_format == "ros2" else _Ros1()
        self._writer = Writer(stream, chunk_size=CHUNK_SIZE, compression=CompressionType.ZSTD)
        self._writer.start(profile=record_format, library=LIBRARY)
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._encoders: dict[str, Encoder] = {}
        self._attached: set[str] = set()
        self._finished = False

    @property
    def record_format(self) -> RecordingFormat:
        return self._format

    def write(
        self, topic: str, type_name: str, message: Mapping[str, Any], log_time_ns: int
    ) -> None:
        """Write ``message`` (ROS 2 field names) of ``type_name`` (``nav_msgs/Path``)."""
        encoding = self._encoding
        channel = self._channels.get(topic)
        if channel is None:
            if type_name not in self._schemas:
                definition = message_definition(encoding.flavour, type_name)
                self._schemas[type_name] = self._writer.register_schema(
                    encoding.schema_name(type_name), encoding.schema_encoding, definition.encode()
                )
                self._encoders[type_name] = encoding.encoder(type_name, definition)
            channel = self._writer.register_channel(
                topic, encoding.message_encoding, self._schemas[type_name]
            )
            self._channels[topic] = channel
        data = self._encoders[type_name](message)
        self._writer.add_message(channel, log_time_ns, data, log_time_ns)

    def write_serialised(
        self, topic: str, type_name: str, definition: str, data: bytes, log_time_ns: int
    ) -> None:
        """Write a message serialised by its publisher, in this file's encoding, as is.

        ``type_name`` and ``definition`` are the publisher's (a ROS 1 connection header's
        ``type`` and ``message_definition``): the schema is registered from them.
        """
        encoding = self._encoding
        channel = self._channels.get(topic)
        if channel is None:
            key = f"published:{type_name}"
            if key not in self._schemas:
                self._schemas[key] = self._writer.register_schema(
                    encoding.schema_name(type_name), encoding.schema_encoding, definition.encode()
                )
            channel = self._writer.register_channel(
                topic, encoding.message_encoding, self._schemas[key]
            )
            self._channels[topic] = channel
        self._writer.add_message(channel, log_time_ns, data, log_time_ns)

    def write_json(
        self, topic: str, schema_file: str, schema: str, data: bytes, log_time_ns: int
    ) -> None:
        """Write one JSON message (``data``, UTF-8) on a ``json`` channel.

        The channel is schemaless, as the MCAP spec allows for ``json``: rosbags (0.11.9)
        refuses to open a file holding a ``jsonschema`` schema at all, which would lose
        every ROS topic for its users. The JSON Schema goes into the file as an
        attachment named ``schema_file``, which the channel's metadata names.
        """
        channel = self._channels.get(topic)
        if channel is None:
            if schema_file not in self._attached:  # once per file (a fleet: a topic a robot)
                self._attached.add(schema_file)
                self._writer.add_attachment(
                    0, log_time_ns, schema_file, "application/schema+json", schema.encode()
                )
            channel = self._writer.register_channel(
                topic, "json", 0, {"schema_attachment": schema_file}
            )
            self._channels[topic] = channel
        self._writer.add_message(channel, log_time_ns, data, log_time_ns)

    def add_metadata(self, name: str, fields: Mapping[str, str]) -> None:
        """Write a metadata record (``name``, string fields)."""
        self._writer.add_metadata(name, dict(fields))

    def flush(self) -> None:
        """Write the open chunk and hand everything to the operating system."""
        if not self._finished:
            self._writer.flush()

    def finish(self) -> None:
        """Write the summary and close the file (once; later calls do nothing)."""
        if self._finished:
            return
        self._finished = True
        try:
            self._writer.finish()
        finally:
            self._stream.close()


class _Ros2:
    """ROS 2: CDR, schemas ``nav_msgs/msg/Path`` in ``ros2msg``."""

    flavour: Literal["ros2"] = "ros2"
    message_encoding = "cdr"
    schema_encoding = "ros2msg"

    @staticmethod
    def schema_name(type_name: str) -> str:
        package, name = type_name.split("/")
        return f"{package}/msg/{name}"

    def encoder(self, type_name: str, definition: str) -> Encoder:
        # mcap_ros2's Writer keeps this encoder to itself and accepts no JSON channel
        # beside its own; the function it uses is the library's, not a copy.
        from mcap_ros2._dynamic import serialize_dynamic

        encode: Encoder = serialize_dynamic(self.schema_name(type_name), definition)[
            self.schema_name(type_name)
        ]
        return encode


class _Ros1:
    """ROS 1: rosbag's encoding, schemas ``nav_msgs/Path`` in ``ros1msg``."""

    flavour: Literal["ros1"] = "ros1"
    message_encoding = "ros1"
    schema_encoding = "ros1msg"

    @staticmethod
    def schema_name(type_name: str) -> str:
        return type_name

    def encoder(self, type_name: str, definition: str) -> Encoder:
        # The genpy that mcap_ros1 bundles (and its own decoder falls back on): Debian's
        # genpy would do too, but navseq's core must not import ROS (tests/test_layers.py).
        from mcap_ros1._vendor.genpy import dynamic

        classes = dynamic.generate_dynamic(type_name, definition)

        def encode(message: Mapping[str, Any]) -> bytes:
            instance = classes[type_name]()
            _fill_ros1(instance, message, classes)
            buffer = io.BytesIO()
            instance.serialize(buffer)
            return buffer.getvalue()

        return encode


def _fill_ros1(instance: Any, values: Mapping[str, Any], classes: Mapping[str, Any]) -> None:
    """Set a generated ROS 1 message's fields from ROS 2-named ``values``, recursively."""
    from mcap_ros1._vendor.genpy.rostime import Duration, Time

    for name, slot_type in zip(instance.__slots__, instance._slot_types, strict=True):
        if name not in values:
            continue
        value = values[name]
        base, _, array = slot_type.partition("[")
        if base in ("time", "duration"):
            kind = Time if base == "time" else Duration
            setattr(instance, name, kind(value["sec"], value["nanosec"]))
        elif base in classes and array:
            items = []
            for item in value:
                element = classes[base]()
                _fill_ros1(element, item, classes)
                items.append(element)
            setattr(instance, name, items)
        elif base in classes:
            _fill_ros1(getattr(instance, name), value, classes)
        else:
            setattr(instance, name, value)


__all__ = ["CHUNK_SIZE", "FORMATS", "McapRecording", "RecordingFormat"]
