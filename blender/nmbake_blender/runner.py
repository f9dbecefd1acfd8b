"""Running the nmbake executable: finding it, its progress line, its one-line error.

No bpy here: the operator feeds it and reads its state. nmbake draws its progress line on stderr
(`--progress`), rewritten in place with carriage returns: "nmbake: tracing  42% [###...] 3.1 s,
about 4.2 s left" or "nmbake: building the BVH, 1.2 s"; an error is one line "error: ..."; the summary
("nmbake: wrote ...") goes to stdout. Both streams are read together by one thread.
"""

import os
import re
import shutil
import subprocess
import threading

# nmbake's --maps names, in its --help order; vertex-color and the IDs are colour data.
MAP_NAMES = (
    "normal",
    "object-normal",
    "ao",
    "bent-normal",
    "height",
    "thickness",
    "curvature",
    "position",
    "object-id",
    "material-id",
    "vertex-color",
)
COLOR_MAPS = ("vertex-color", "object-id", "material-id")

_PROGRESS = re.compile(r"^nmbake: (?P<stage>[a-z][a-zA-Z' -]*?)(?:,| +(?P<percent>\d+)%)")


class NotFound(Exception):
    pass


def find_executable(setting):
    """The absolute path of the nmbake executable named by the preferences' `setting` (a path, or a
    bare name looked up on PATH; empty: "nmbake"). Raises NotFound with a one-line message."""
    name = (setting or "").strip() or "nmbake"
    if os.sep in name or name.startswith("~") or name.startswith("//"):
        path = os.path.abspath(os.path.expanduser(name))
        if os.path.isfile(path) and os.access(path, os.X_OK):
            return path
        raise NotFound("nmbake executable not found: %s is not an executable file (set its path in the add-on's preferences)" % path)
    path = shutil.which(name)
    if path is None:
        raise NotFound("nmbake executable not found: %r is not on PATH (install nmbake or set its path in the add-on's preferences)" % name)
    return path


def parse_progress(line):
    """(stage, percent or None) of a progress line, or None for another line."""
    m = _PROGRESS.match(line)
    if m is None or m.group("stage").startswith(("wrote", "warning", "automatic cage", "cage")):
        return None
    percent = m.group("percent")
    return m.group("stage"), (int(percent) if percent is not None else None)


class Run:
    """One nmbake process; a thread reads its output. Poll `done`; then `returncode`, `error`
    (nmbake's "error: ..." line, else the output's last line) and `lines` (every line but the
    progress)."""

    def __init__(self, command, on_line=None):
        self.command = command
        self.lines = []
        self.stage, self.percent = "starting", None
        self.returncode = None
        self._on_line = on_line
        self._lock = threading.Lock()
        self._process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def _read(self):
        pending = b""
        while True:
            chunk = self._process.stdout.read1(4096) if hasattr(self._process.stdout, "read1") else self._process.stdout.read(4096)
            if not chunk:
                break
            pending += chunk
            parts = re.split(rb"[\r\n]", pending)
            pending = parts.pop()
            for part in parts:
                self._line(part)
        if pending:
            self._line(pending)
        self._process.wait()
        self.returncode = self._process.returncode

    def _line(self, raw):
        line = raw.decode("utf-8", "replace").strip()
        if not line:
            return
        progress = parse_progress(line)
        with self._lock:
            if progress is not None:
                self.stage, self.percent = progress
            else:
                self.lines.append(line)
        if self._on_line is not None:
            self._on_line(line, progress)

    @property
    def done(self):
        return self.returncode is not None

    def wait(self, timeout=None):
        self._thread.join(timeout)
        return self.done

    def cancel(self):
        """SIGTERM: nmbake stops and writes nothing (exit 143)."""
        if self._process.poll() is None:
            self._process.terminate()

    def status_text(self):
        with self._lock:
            if self.percent is None:
                return "nmbake: " + self.stage
            return "nmbake: %s %d%%" % (self.stage, self.percent)

    @property
    def error(self):
        """nmbake's one-line error as "nmbake: ..." (Blender prefixes its reports with "Error:")."""
        with self._lock:
            for line in reversed(self.lines):
                if line.startswith("error:"):
                    return "nmbake: " + line[len("error:") :].strip()
            if self.returncode is not None and self.returncode < 0:
                return "nmbake was killed by signal %d" % -self.returncode
            return self.lines[-1] if self.lines else "nmbake exited with code %s" % self.returncode
