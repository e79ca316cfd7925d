"""Assertion shared by the tests of unreadable logs."""

from __future__ import annotations

import pytest

from greybox.data.io import read_log
from greybox.errors import LogError


def assert_read_fails(path, *fragments, **options) -> str:
    """Assert that ``read_log(path, **options)`` raises a :class:`LogError` naming ``path``.

    The message must start with ``"<path>: "`` and contain every fragment; it is returned.
    """
    with pytest.raises(LogError) as error:
        read_log(path, **options)
    message = str(error.value)
    assert message.startswith(str(path) + ": "), message
    for fragment in fragments:
        assert fragment in message, message
    return message
