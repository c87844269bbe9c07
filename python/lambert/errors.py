"""The exceptions of lambert: every library error is a :class:`Error`.

Bad input (a scene, an array, an option value) raises :class:`InputError` or
:class:`UsageError`, both also :class:`ValueError`; a computation that fails raises
:class:`ComputeError` (also :class:`RuntimeError`). Messages are the CLI's.
"""


class Error(Exception):
    """Base class of every lambert error."""


class InputError(Error, ValueError):
    """A bad scene, array or view-factor file (the CLI's exit code 2)."""


class UsageError(Error, ValueError):
    """A bad option value or combination (the CLI's exit code 2)."""


class UnsupportedError(Error, ValueError):
    """The method cannot treat this configuration (the CLI's exit code 2)."""


class ComputeError(Error, RuntimeError):
    """The computation failed: singular system, leaking enclosure (the CLI's exit code 1)."""


class LambertIOError(Error, OSError):
    """A file could not be written (the CLI's exit code 1)."""


class LambertWarning(UserWarning):
    """What a computation reported about its accuracy or the scene (the CLI's warnings)."""
