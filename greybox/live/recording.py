"""Recordings of a live stream: rolling Parquet files of the table ``greybox predict`` writes.

The estimates go to ``DIR/live-<start>-<n>.parquet``, a new file every ``every_s`` seconds of log time
and at the start of every run (after a gap). So that a hard kill (SIGKILL, out of memory, power loss)
loses at most a second of them, the estimates of the file being filled are also written every
``flush_s`` seconds (of log time, or of wall-clock time while the stream is quiet) as part files
``DIR/live-<start>-<n>.part-<k>.parquet``, each a complete Parquet file of the rows since the previous
part; once the whole file is written its parts are removed. After a kill, the part files left hold the
estimates of the file that was being filled, readable as they stand. A file complete is written through
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

__all__ = ["DEFAULT_RECORD_S", "DEFAULT_FLUSH_S", "Recorder"]

#: Log seconds per recording file by default.
DEFAULT_RECORD_S = 60.0

#: Seconds between two part files by default: a part in the writing and one being filled, at most a second.
DEFAULT_FLUSH_S = 0.5


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
    flush_s : float or None, default DEFAULT_FLUSH_S
        Seconds (of log time, or of wall-clock time) between two part files; None: none.

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
                 every_s: float = DEFAULT_RECORD_S, attrs: dict | None = None,
                 flush_s: float | None = DEFAULT_FLUSH_S):
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
        self.flush_s = None if flush_s is None else float(flush_s)
        self.written: list[Path] = []
        self._flushed = 0  # parts of the file being filled already in part files
        self._part_files: list[Path] = []
        self._flushed_s = time.monotonic()
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
        elif self.flush_s is not None:
            unflushed_s = float(result.time[-1]) - float(self._parts[self._flushed].time[0])
            if unflushed_s >= self.flush_s or time.monotonic() - self._flushed_s >= self.flush_s:
                self.flush()

    def flush(self) -> Path | None:
        """Hand the estimates added since the last part to the writer as the next part file; None when none.

        Raises
        ------
        GreyboxError
            When an earlier file could not be written.
        """
        self._flushed_s = time.monotonic()
        self._collect(wait=False)
        if self.flush_s is None or self._flushed >= len(self._parts):
            return None
        parts, self._flushed = self._parts[self._flushed:], len(self._parts)
        path = self.directory / f"live-{self._stamp}-{self._files:05d}.part-{len(self._part_files):04d}.parquet"
        self._part_files.append(path)
        live = {"file": self._files, "run": self._run, "part": len(self._part_files) - 1}
        self._writing.append((self._submit(self._write, parts, path, live), None))
        return path

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
        part_files, self._part_files, self._flushed = self._part_files, [], 0
        self._writing.append((self._submit(self._write_whole, parts, path, live, part_files), path))
        return path

    def _submit(self, *task) -> Future:
        if self._writer is None:
            self._writer = ThreadPoolExecutor(max_workers=1, thread_name_prefix="greybox-record")
        return self._writer.submit(*task)

    def _write_whole(self, parts: list, path: Path, live: dict, part_files: list) -> None:
        """Write one whole file, then remove its part files (the writer runs one task at a time, in order)."""
        self._write(parts, path, live)
        for part in part_files:
            part.unlink(missing_ok=True)

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
            if path is not None:  # a whole file (not a part)
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
