"""Replay an axis log to an MQTT broker at real time, as a controller streams it: the publisher for ``greybox live``.

Each message is a batch of ``--batch`` samples as JSON columns with the log's column names (``time_s``,
``position_mm``, ``velocity_mm_s``, ``current_A``) and a ``seq`` tag, sent when the log time of its last
sample is due (``--speed`` 2 replays twice as fast). See docs/live.md.

    python scripts/replay_live.py data/X_D.mcap mqtt://127.0.0.1:1883/axis/X --batch 10
"""

from __future__ import annotations

import argparse
import json
import sys
import time


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log", help="axis log (any format greybox reads)")
    parser.add_argument("target", help="mqtt://HOST[:PORT]/TOPIC")
    parser.add_argument("--batch", type=int, default=10, help="samples per message (default 10)")
    parser.add_argument("--speed", type=float, default=1.0, help="replay speed, 1 = real time (default)")
    parser.add_argument("--axis", help="the axis to read from a log of several")
    args = parser.parse_args(argv)
    if args.batch < 1 or not args.speed > 0:
        parser.error("--batch must be at least 1 and --speed positive")

    import paho.mqtt.client as mqtt

    from greybox.data.io import read_log
    from greybox.errors import GreyboxError
    from greybox.live.broker import parse_address

    try:
        address = parse_address(args.target, "TARGET")
        log = read_log(args.log, axis=args.axis)
    except GreyboxError as error:
        print(f"replay_live: error: {error}", file=sys.stderr)
        return 2
    units = log.units
    columns = {"time_s": log.time, units.position_column: log.position, f"{log.effort_column}": log.effort}
    if log.velocity is not None:
        columns[units.velocity_column] = log.velocity
    client = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2)
    client.connect(address.host, address.port)
    client.loop_start()
    start_wall, start_log = time.monotonic(), float(log.time[0])
    sent = 0
    try:
        for seq, first in enumerate(range(0, len(log), args.batch)):
            stop = min(first + args.batch, len(log))
            due = start_wall + (float(log.time[stop - 1]) - start_log) / args.speed
            pause = due - time.monotonic()
            if pause > 0:
                time.sleep(pause)
            payload = {name: values[first:stop].tolist() for name, values in columns.items()}
            payload["seq"] = seq
            client.publish(address.topic, json.dumps(payload, separators=(",", ":")))
            sent += stop - first
    except KeyboardInterrupt:
        pass
    finally:
        client.disconnect()
        client.loop_stop()
    print(f"replayed {sent} of {len(log)} samples of {args.log} to {address} in "
          f"{time.monotonic() - start_wall:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
