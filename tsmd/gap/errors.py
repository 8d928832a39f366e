"""The error `tsmd gap` reports to a user as one line."""

from tsmd.errors import TsmdError


class GapError(TsmdError, ValueError):
    """Input the gap diagnosis cannot use; the message names the recording, column and reason."""
