"""The base of every error tsmd reports to a user as a message instead of a traceback."""


class TsmdError(Exception):
    """An error whose message names the problem (file, key, value, reason) for the user."""
