"""Development check of ``greybox live --envelope`` on a twin part series (the head to head's seed 101).

A re-levelled force envelope is taught on parts 1-10 (cut by the series' part counter); the estimates of parts
1-N (``greybox predict`` of the series, the columns ``greybox live`` gives) are fed to an
:class:`~greybox.live.envelope.EnvelopeWatch` in messages of 50 samples; it prints the alarms raised per part of
the stream and the time the watch took per message:

    python scripts/process_live_dev.py MODEL SERIES.mcap [N]
"""

from __future__ import annotations

import sys
import time
import warnings
from collections import Counter

import numpy as np

from greybox.data.axis_config import read_axis_config
from greybox.data.reading import read_prepared
from greybox.live.envelope import EnvelopeWatch
from greybox.models.files import load_model
from greybox.predict.process import predict_process
from greybox.process.alignment import part_slices
from greybox.process.envelope import Envelope
from greybox.process.parts import Part, PartSignal

AXIS = "examples/axis_x.toml"


def main(model_path: str, series: str, last: int) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a model file without a digest: said by greybox itself elsewhere
        model = load_model(model_path)
    source = PartSignal(model=model_path, axis_config=AXIS)
    run = read_prepared(series, {})[0]
    counter = run.extras["part"]
    log = run.select(slice(0, int(np.flatnonzero(counter <= last)[-1]) + 1))
    taught = []
    for part in part_slices(log.velocity, counter=log.extras["part"], sample_time=log.sample_time)[:10]:
        piece = log.select(part)
        found = source.signal([piece])
        taught.append(Part(series, int(piece.extras["part"][0]), float(piece.time[0]), found["time"] - piece.time[0],
                           found["velocity"], found["signal"], {}, found["level"], found["current"], found["convert"]))
    envelope = Envelope(relevel=True).fit(taught, unit="N", signal={"kind": "force"})
    config = read_axis_config(AXIS)
    columns = predict_process(model, [log], axis_config=config).columns()
    watch = EnvelopeWatch(envelope, kind="force", convert=config.process_load)
    n, times, alarms = columns["time_s"].size, [], []
    for start in range(0, n, 50):
        began = time.perf_counter()
        alarms += watch.check({name: values[start:start + 50] for name, values in columns.items()})
        times.append(1e3 * (time.perf_counter() - began))
    alarms += watch.rearm(float(columns["time_s"][-1]))
    print(f"{n} samples ({n * log.sample_time:.0f} s, parts 1-{last}), {len(times)} messages of 50: per message "
          f"median {np.median(times):.2f} ms, 99th percentile {np.percentile(times, 99):.2f} ms, "
          f"largest {max(times):.1f} ms")
    raised = [alarm for alarm in alarms if alarm.state == "raised"]
    print("alarms raised per part of the stream:", dict(Counter(alarm.part for alarm in raised)))
    for number in sorted({alarm.part for alarm in raised}):
        first = [alarm for alarm in raised if alarm.part == number][:2]
        print(number, "; ".join(f"{'whole part: ' if a.whole_part else ''}{a.kind} from t = {a.since_s:.3f} s, "
                                f"seen at t = {a.time_s:.3f} s" for a in first))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 80)
