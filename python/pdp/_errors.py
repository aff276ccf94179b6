"""The errors pdp raises: the library's message, and in ``quantity`` the
setting (option name) that would fix the problem, or None."""


class PdpError(Exception):
    """Base of pdp's errors."""

    quantity = None


class InputError(PdpError, ValueError):
    """Input data that cannot be used: a recording, a model file, results.
    The message names the file (or "array"), what is wrong and the fix."""


class OptionError(PdpError, ValueError):
    """An option that is wrong or missing; ``quantity`` names it."""


class OutputError(PdpError, OSError):
    """An output that cannot be written."""
