"""Errors raised for bad input."""


class PresetError(ValueError):
    """A preset file that cannot be used: the message names the file, the key and what was
    expected, on one line."""
