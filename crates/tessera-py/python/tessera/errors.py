"""The exceptions tessera raises.

Every one is a :class:`tessera.Error`, and also the built-in exception a Python caller
expects for its kind: a malformed file is a ``ValueError``, a file that cannot be read an
``OSError``, an output refused for its size a ``MemoryError``. The message is the library's
and names the file, the line and the reason (``teapot.patches:14: expected 16 indices``);
``file`` and ``line`` carry them as attributes where they apply.
"""

from __future__ import annotations

from typing import Any, Optional


class Error(Exception):
    """Base class of every tessera error.

    Attributes:
        file: the input (or output) file the error is about, when there is one.
        line: the 1-based line in ``file``, when the error is tied to one.
    """

    file: Optional[str]
    line: Optional[int]

    def __init__(self, message: str, *, file: Optional[str] = None, line: Optional[int] = None, **extra: Any):
        super().__init__(message)
        self.file = file
        self.line = line
        for key, value in extra.items():
            setattr(self, key, value)


class ParseError(Error, ValueError):
    """The input is malformed: syntax, counts, indices, non-finite numbers, a bad tag line."""


class UnsupportedInputError(Error, ValueError):
    """The input is well formed but cannot be used: an unknown extension, a polygon where a
    triangle is needed, a non-manifold subdivision cage, a mesh with no usable face."""


class ParameterError(Error, ValueError):
    """An argument is out of range, or the scheme, criterion and surface do not go together
    (a tolerance for a hardware partitioning, SD-2 on quads, a view criterion without a
    camera)."""


class MeshError(Error, ValueError):
    """A mesh handed to a writer or a check is invalid, or exceeds what its format holds."""


class FileError(Error, OSError):
    """A file could not be read or written."""


class OutputTooLargeError(Error, MemoryError):
    """The output would exceed the memory or triangle limit (``max_triangles``); it was
    refused before anything of its size was allocated.

    Attributes:
        vertices, triangles: the output's exact size.
        bytes: the memory its buffers would need.
    """

    vertices: int
    triangles: int
    bytes: int


__all__ = [
    "Error",
    "ParseError",
    "UnsupportedInputError",
    "ParameterError",
    "MeshError",
    "FileError",
    "OutputTooLargeError",
]
