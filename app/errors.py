"""The one error every command may raise for bad input, and how ``ribbonwave`` reports it (escaped for the terminal)."""


class InputError(Exception):
    """Bad input the user can fix (any command): one line on stderr, exit status 1."""


def printable(message: str) -> str:
    """``message`` with its control characters escaped (``\\x1b``, ``\\r``): a file's name or bytes
    quoted in a message (an escape sequence) never act on the terminal."""
    return "".join(c if c.isprintable() or c == "\n" else repr(c)[1:-1] for c in message)
