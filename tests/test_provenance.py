"""Reports record the versions and the machine their figures were measured with."""

from __future__ import annotations

import numpy as np
import sklearn

from greybox.provenance import provenance, provenance_line


def test_provenance_names_the_versions_in_use_and_the_cores():
    info = provenance()
    assert info["libraries"]["numpy"] == np.__version__
    assert info["libraries"]["scikit-learn"] == sklearn.__version__
    assert isinstance(info["cpu_count"], int) and info["cpu_count"] >= 1
    line = provenance_line(info)
    assert f"numpy {np.__version__}" in line and f"{info['cpu_count']} cores" in line
