"""Exceptions: one per status code of the C library (include/pfsph.h), each carrying the
library's message as the pfsph program prints it."""


class Error(Exception):
    """A pfsph call failed. ``code`` is the C status (``PFSPH_E*``), ``message`` the library's
    full message (file, JSON path, value), which is also ``str(e)``."""

    def __init__(self, message, code=None):
        super().__init__(message)
        self.message = message
        self.code = code


class InputError(Error, ValueError):
    """Invalid input other than a scene: a bad argument, field or value written (PFSPH_EINPUT)."""


class SceneError(InputError):
    """A scene that does not load: ``message`` as ``pfsph run`` prints it (after ``pfsph: ``),
    split into ``source`` (the file, or ``<scene>`` for a dict), ``path`` (the JSON path, e.g.
    ``$.solver.bogus``) and ``reason``. ``key`` is the path's last key (``bogus``), or None when
    the path ends in an index or is ``$``."""

    def __init__(self, message, code=None):
        super().__init__(message, code)
        self.source, self.path, self.reason = _split(message)
        self.key = _last_key(self.path)


class UnstableError(Error, ArithmeticError):
    """The simulation blew up (PFSPH_EUNSTABLE); the message names the particle and the stage."""


class InterruptedRun(Error):
    """A stop was asked for (PFSPH_EINTR): the run ended at a step boundary, resumable."""


class PfsphIOError(Error, OSError):
    """A file system error (PFSPH_EIO)."""


class PfsphMemoryError(Error, MemoryError):
    """Out of memory (PFSPH_ENOMEM)."""


def _split(msg):
    """'<file>: <JSON path>: <reason>' -> (file, path, reason); path None when absent."""
    i = msg.find(": $")
    if i < 0:
        return None, None, msg
    rest = msg[i + 2:]
    j = rest.find(": ")
    if j < 0:
        return msg[:i], rest, ""
    return msg[:i], rest[:j], rest[j + 2:]


def _last_key(path):
    if not path or path == "$":
        return None
    # "$.phases[0].viscosity" -> "viscosity", "$.fluid[2]" -> "fluid"
    return path.rsplit(".", 1)[-1].split("[", 1)[0] or None


_CODES = {-2: InputError, -3: UnstableError, -4: InterruptedRun, -5: PfsphIOError, -12: PfsphMemoryError}


def from_code(code, message, scene=False):
    """The exception of a C status code (scene=True: an EINPUT is a SceneError)."""
    if scene and code == -2:
        return SceneError(message, code)
    return _CODES.get(code, Error)(message, code)
