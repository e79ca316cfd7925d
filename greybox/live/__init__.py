"""The process current and force of a live stream (``greybox live``), as exact as ``greybox predict``.

Modules, one concept each: :mod:`~greybox.live.messages` (the message format), :mod:`~greybox.live.broker`
(MQTT addresses and connections), :mod:`~greybox.live.source_base` (what every source gives),
:mod:`~greybox.live.sources` (stdin, MQTT), :mod:`~greybox.live.opcua` and :mod:`~greybox.live.opcua_samples`
(an OPC UA server's variables), :mod:`~greybox.live.sinks`, :mod:`~greybox.live.timeline` (time stamps,
gaps), :mod:`~greybox.live.lookahead` (the derivatives as offline), :mod:`~greybox.live.estimator` (the
model's state across messages), :mod:`~greybox.live.limits` (alarms), :mod:`~greybox.live.recording`
(rolling Parquet files), :mod:`~greybox.live.stats` (the counters), :mod:`~greybox.live.session` (one
stream, message by message) and :mod:`~greybox.live.run` (the command as one function).
"""
