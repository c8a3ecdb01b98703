"""Errors raised for bad input."""


class PresetError(ValueError):
    """A preset file that cannot be used: the message names the file, the key and what was
    expected, on one line."""


class QSMError(PresetError):
    """A TreeQSM cylinder model that cannot be used: one line naming the file, the row (the
    cylinder's number, 1-based as TreeQSM counts) and what was wrong."""
