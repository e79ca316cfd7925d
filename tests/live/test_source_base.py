"""The interface every source of ``greybox live`` implements, in a module that imports nothing else of greybox."""

from __future__ import annotations

import ast
import inspect

import pytest

from greybox.live import source_base
from greybox.live.opcua import OpcUaSource
from greybox.live.source_base import Source
from greybox.live.sources import LineSource, MqttSource


def test_the_base_imports_nothing_of_the_package():
    tree = ast.parse(inspect.getsource(source_base))
    imported = [node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)]
    imported += [alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names]
    assert imported and not [name for name in imported if name.startswith(("greybox", "."))], imported


@pytest.mark.parametrize("kind", [LineSource, MqttSource, OpcUaSource])
def test_every_source_implements_it(kind):
    assert issubclass(kind, Source) and not inspect.isabstract(kind)


def test_a_source_without_iteration_cannot_be_made():
    class Half(Source):
        def close(self):
            """Nothing."""

    with pytest.raises(TypeError):
        Half()
