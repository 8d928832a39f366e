"""The base of every error tsmd reports to a user as a message instead of a traceback."""


class TsmdError(Exception):
    """An error whose message names the problem (file, key, value, reason) for the user."""


class DaemonError(TsmdError):
    """The daemon could not start (drives, profile, socket); the message says which and why."""

    def __init__(self, message: str, code: str = "daemon") -> None:
        super().__init__(message)
        self.code = code
