"""Recordings of a live stream: rolling Parquet files of the table ``greybox predict`` writes.

The estimates go to ``DIR/live-<start>-<n>.parquet``, a new file every ``every_s`` seconds of log time
and at the start of every run (after a gap). A file complete is written through
:func:`greybox.predict.output.write_process_blocks` (atomically: a file is there whole or not at all;
no file is overwritten) by a writer thread of its own, so that the stream does not wait for it (a minute
of estimates takes a tenth of a second or more to write); closing the recorder waits for every file. Its
columns and metadata are those of ``greybox predict``'s Parquet output, with the file's place in the stream
under ``attrs["live"]``. Memory holds the estimates of the file being filled and of the one being written.
"""

from __future__ import annotations

import time
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

from ..data.axis_config import AxisConfig
from ..errors import GreyboxError
from ..predict.output import write_process_blocks
from ..predict.process import ProcessResult, ProcessTally, join_results, process_attrs

__all__ = ["DEFAULT_RECORD_S", "Recorder"]

#: Log seconds per recording file by default.
DEFAULT_RECORD_S = 60.0


class Recorder:
    """Writes the estimates of a stream into rolling Parquet files.

    Parameters
    ----------
    directory : path-like
        Folder of the files (created if missing).
    model : CurrentModel
        The model (its kind goes into the metadata).
    axis_config : AxisConfig, optional
        Drive-train constants used (into the metadata).
    chunk_s : float
        Chunk length [s] of the model (into the metadata).
    every_s : float, default 60.0
        Log seconds per file.
    attrs : dict, optional
        Further metadata entries (model file, source).

    Attributes
    ----------
    written : list of pathlib.Path
        Files written so far (all of them once :meth:`close` returned).

    Raises
    ------
    GreyboxError
        When the folder cannot be created.
    """

    def __init__(self, directory, *, model, axis_config: AxisConfig | None = None, chunk_s: float,
                 every_s: float = DEFAULT_RECORD_S, attrs: dict | None = None):
        self.directory = Path(directory)
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise GreyboxError(f"--record {directory}: cannot create the folder ({exc.strerror})") from None
        if not self.directory.is_dir():
            raise GreyboxError(f"--record {directory}: not a folder")
        self.model = model
        self.axis_config = axis_config
        self.chunk_s = float(chunk_s)
        self.every_s = float(every_s)
        self.attrs = dict(attrs or {})
        self.written: list[Path] = []
        self._stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
        self._parts: list[ProcessResult] = []
        self._start_s: float | None = None
        self._run = 0
        self._files = 0  # files handed to the writer
        self._writer: ThreadPoolExecutor | None = None
        self._writing: list[tuple[Future, Path]] = []

    def add(self, result: ProcessResult) -> None:
        """Take the estimates of consecutive samples; write the file once it spans ``every_s``.

        Parameters
        ----------
        result : ProcessResult
            Estimates of samples after those added before (of the same run).
        """
        if not len(result.time):
            return
        if self._start_s is None:
            self._start_s = float(result.time[0])
        self._parts.append(result)
        if float(result.time[-1]) - self._start_s >= self.every_s:
            self.close_file()

    def new_run(self) -> None:
        """A new run starts (after a gap): the current file is closed."""
        self.close_file()
        self._run += 1

    def close_file(self) -> Path | None:
        """Hand the estimates held to the writer thread as the next file; None when none are held.

        Raises
        ------
        GreyboxError
            When an earlier file could not be written.
        """
        self._collect(wait=False)
        if not self._parts:
            return None
        parts, self._parts, self._start_s = self._parts, [], None
        live = {"file": self._files, "run": self._run}
        path = self._next_path()
        if self._writer is None:
            self._writer = ThreadPoolExecutor(max_workers=1, thread_name_prefix="greybox-record")
        self._writing.append((self._writer.submit(self._write, parts, path, live), path))
        return path

    def _write(self, parts: list, path: Path, live: dict) -> None:
        """Write one file (in the writer thread): the parts joined into one block, the metadata with ``live``."""
        first = parts[0]
        # one block, one row group: a row group per message (thousands of a few rows each) took seconds to
        # write and read back, the stream waiting meanwhile
        joined = join_results(parts, {}) if len(parts) > 1 else parts[0]
        tally = ProcessTally()
        tally.add(joined)
        attrs = process_attrs(self.model, axis_config=self.axis_config, interval=None, chunk_s=self.chunk_s,
                              motion=first.motion, effort_unit=first.effort_unit, tally=tally)
        attrs.pop("extrapolation", None)  # counted per file without the per-quantity flags: not comparable
        attrs.update(self.attrs)
        attrs["live"] = {**live, "start_s": float(first.time[0]), "stop_s": float(joined.time[-1]),
                         "samples": len(joined.time)}
        metadata = {"axis": first.axis, "dataset": first.dataset or "", "effort_unit": first.effort_unit,
                    "attrs": attrs}
        write_process_blocks([joined], path, metadata=lambda: metadata)

    def _next_path(self) -> Path:
        index = self._files
        while True:
            path = self.directory / f"live-{self._stamp}-{index:05d}.parquet"
            index += 1
            if not path.exists():
                self._files = index
                return path

    def _collect(self, *, wait: bool) -> None:
        """Count the files the writer finished (all of them with ``wait``); raise the error of one that failed."""
        while self._writing and (wait or self._writing[0][0].done()):
            future, path = self._writing.pop(0)
            future.result()
            self.written.append(path)

    def close(self) -> None:
        """Write the estimates still held, and wait until every file is written.

        Raises
        ------
        GreyboxError
            When a file could not be written.
        """
        try:
            self.close_file()
            self._collect(wait=True)
        finally:
            if self._writer is not None:
                self._writer.shutdown(wait=True)
                self._writer = None
