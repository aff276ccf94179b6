"""The errors pdp raises: the library's message, ending with the keyword
that would fix the problem ("(keyword filter_a)") when there is one, and in
``quantity`` that option's declared name ("filter-a"; several
comma-separated), or None."""


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
