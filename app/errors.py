"""The one error every command may raise for bad input, and how ``ribbonwave`` reports it."""


class InputError(Exception):
    """Bad input the user can fix (any command): one line on stderr, exit status 1."""
