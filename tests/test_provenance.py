"""Reports record the versions and the machine their figures were measured with."""

from __future__ import annotations

import numpy as np
import sklearn

from greybox.provenance import file_sha256, provenance, provenance_line


def test_provenance_names_the_versions_in_use_and_the_cores():
    info = provenance()
    assert info["libraries"]["numpy"] == np.__version__
    assert info["libraries"]["scikit-learn"] == sklearn.__version__
    assert isinstance(info["cpu_count"], int) and info["cpu_count"] >= 1
    line = provenance_line(info)
    assert f"numpy {np.__version__}" in line and f"{info['cpu_count']} cores" in line


def test_file_sha256_is_of_the_bytes(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    one.write_bytes(b"abc")
    two.write_bytes(b"abd")
    assert file_sha256(one) == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    assert file_sha256(two) != file_sha256(one)
