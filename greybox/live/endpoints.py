"""The source, the sink and the status topic of ``greybox live``, opened and checked together.

The source is stdin, an MQTT topic or an OPC UA server's variables (:mod:`greybox.live.opcua`); the sink
stdout or an MQTT topic.

The source and the sink are opened with one client id (``<id>-in``, ``<id>-out``). The status topic
(``<sink topic>/status`` by default with an MQTT sink) goes out through the sink's connection, or through
the source's when the estimates go to stdout; that connection's will is the ``offline`` status. A sink on
the source's broker whose topics the source's filter would receive (the estimates, the alarms, the
status) is refused before anything is opened: the command would read its own output.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence, TextIO

from ..errors import GreyboxError
from .broker import BrokerOptions, default_client_id, is_address, parse_address, topic_matches
from .opcua import OpcUaOptions, OpcUaSource, is_opcua_address, parse_opcua_address
from .sinks import LineSink, MqttSink
from .sources import LineSource, MqttSource
from .status import StatusTopic, will_message

__all__ = ["Endpoints", "open_endpoints"]


@dataclass
class Endpoints:
    """What a live stream reads, writes and reports its status to.

    Attributes
    ----------
    stream : Source
        The source (:class:`~greybox.live.source_base.Source`: stdin lines, MQTT or OPC UA).
    out : LineSink or MqttSink
        The sink.
    status : StatusTopic or None
        The status topic, when there is a broker to hold it.
    """

    stream: object
    out: object
    status: StatusTopic | None

    def close(self) -> None:
        """Close the source and the sink."""
        try:
            self.stream.close()
        finally:
            self.out.close()


def _output_topics(sink_topic: str, axes: Sequence[str | None], columns: Sequence[str]) -> list[str]:
    topics = []
    for axis in axes:
        base = sink_topic if axis is None else f"{sink_topic}/{axis}"
        topics += [base] + [f"{base}/alarm/{column}" for column in columns]
    return topics


def open_endpoints(source: str, sink: str, *, options: BrokerOptions, status_topic: str | None = None,
                   axes: Sequence[str | None] = (None,), limit_columns: Sequence[str] = (),
                   opcua: OpcUaOptions | None = None, stdin: TextIO, stdout: TextIO) -> Endpoints:
    """Open the source and the sink (and the status topic), after checking that they do not loop.

    Parameters
    ----------
    source : str
        ``-``, ``mqtt[s]://[USER@]HOST[:PORT]/TOPIC`` (wildcards allowed) or ``opc.tcp://[USER@]HOST[:PORT]``.
    sink : str
        ``-`` or ``mqtt[s]://[USER@]HOST[:PORT]/TOPIC``.
    options : BrokerOptions
        Log-in, TLS, client id, QoS, session, queue (of both connections).
    status_topic : str, optional
        The status topic; default ``<sink topic>/status`` with an MQTT sink, none otherwise.
    axes : sequence of str or None, default (None,)
        The axes of a machine (their estimates go to ``<sink topic>/<axis>``), or ``(None,)``.
    limit_columns : sequence of str, default ()
        The columns with limits (their alarms go to ``.../alarm/<column>``).
    opcua : OpcUaOptions, optional
        The variables, log-in and subscription of an ``opc.tcp://`` source (needed with one, refused otherwise).
    stdin, stdout : text file
        The streams of ``-``.

    Raises
    ------
    GreyboxError
        For an address that cannot be read, a sink whose topics the source would receive, a status topic
        without a broker, or a broker that cannot be reached or refuses the connection.
    """
    server_at = parse_opcua_address(source) if is_opcua_address(source) else None
    if source != "-" and not is_address(source) and server_at is None:
        raise GreyboxError(f"--source {source}: give '-' (lines on stdin), mqtt://HOST[:PORT]/TOPIC or "
                           "opc.tcp://HOST[:PORT]")
    if sink != "-" and not is_address(sink):
        raise GreyboxError(f"--sink {sink}: give '-' (lines on stdout) or mqtt://HOST[:PORT]/TOPIC")
    if (server_at is None) != (opcua is None):
        raise GreyboxError("--node applies to an opc.tcp:// source" if server_at is None else
                           f"--source {server_at}: give the variables to read, --node COLUMN=NODEID each")
    source_at = parse_address(source, "--source") if source != "-" and server_at is None else None
    sink_at = parse_address(sink, "--sink", wildcards=False) if sink != "-" else None
    if status_topic is None and sink_at is not None:
        status_topic = f"{sink_at.topic}/status"
    if status_topic is not None:
        if sink_at is None and source_at is None:
            raise GreyboxError("--status-topic needs a broker: an MQTT --source or --sink")
        parse_address(f"mqtt://host/{status_topic}", "--status-topic", wildcards=False)
    if source_at is not None:
        published = [status_topic] if status_topic is not None and sink_at is None else []
        if sink_at is not None and (sink_at.host, sink_at.port) == (source_at.host, source_at.port):
            published += _output_topics(sink_at.topic, axes, limit_columns)
            published += [status_topic] if status_topic is not None else []
        looped = [topic for topic in published if topic_matches(source_at.topic, topic)]
        if looped:
            raise GreyboxError(f"--sink {sink_at or status_topic}: the source's topic filter {source_at.topic} "
                               f"receives {looped[0]}, where the command publishes: it would read its own output; "
                               "give the sink a topic outside the filter")
    options = _completed(options, [address for address in (source_at, sink_at) if address is not None])
    will = (status_topic, will_message(options.client_id)) if status_topic is not None else None
    if server_at is not None:
        stream = OpcUaSource(server_at, opcua)
    elif source_at is None:
        stream = LineSource(stdin)
    else:
        stream = MqttSource(source_at, options, will=will if sink_at is None else None)
    try:
        out = LineSink(stdout) if sink_at is None else MqttSink(sink_at, options, will=will)
    except BaseException:
        stream.close()
        raise
    status = None
    if status_topic is not None:  # a broker carries it: the sink's, or else the source's
        status = StatusTopic((out if sink_at is not None else stream).connection, status_topic, options.client_id)
    return Endpoints(stream, out, status)


def _completed(options: BrokerOptions, addresses) -> BrokerOptions:
    """The options with a client id, and with the user name of an address (one user for the source and sink)."""
    from dataclasses import replace

    names = {address.username for address in addresses if address.username} | (
        {options.username} if options.username else set())
    if len(names) > 1:
        raise GreyboxError("the user names of --source, --sink and --username differ: give one user name")
    return replace(options, client_id=options.client_id or default_client_id(),
                   username=next(iter(names)) if names else None)
