"""Watching the cut over repeated parts: teach-in envelopes of the process force and their checks.

:mod:`~greybox.process.alignment` finds the parts of a log and aligns one part to another;
:mod:`~greybox.process.parts` computes the watched signal (a model's process force or current, or the raw
current); :mod:`~greybox.process.envelope` learns the envelope from good parts; :mod:`~greybox.process.check`
checks a part against it, :mod:`~greybox.process.watch` while it is cut;
:mod:`~greybox.process.report` writes the report; :mod:`~greybox.process.run` are the
two workflows behind ``greybox process teach`` and ``greybox process check``.
"""
