# SPDX-License-Identifier: GPL-3.0-or-later
"""The files one job writes: all of them, or none.

Every output path is checked when it is declared, before the job starts (a
folder given as a file, a folder that cannot be written, a wrong extension),
by creating and removing a probe file next to it. Writers write to a
temporary name in the same folder; `commit()` checks that each file was
really written (Blender's exporters fail silently on some paths) and only
then renames them into place. A failed, cancelled or interrupted job leaves
no new file, and an existing file at an output path untouched.

No bpy here: the CLI and the tests use it alike.
"""

import os


class OutputPathError(ValueError):
    """An output path cannot be written; the message names the option."""


class OutputFiles:
    """Use as a context manager: the files are committed when the block ends
    normally and discarded when it raises (KeyboardInterrupt included)."""

    def __init__(self):
        self._files = []  # (option, final path, temporary path)
        self._new_folders = []

    def add(self, option, path, allowed):
        """Declare an output; returns the temporary path to write it to."""
        final = os.path.abspath(path)
        if os.path.isdir(final):
            raise OutputPathError(f"{option}: {path} is a folder; give a file name, e.g. "
                                  f"{os.path.join(path, 'result' + allowed[0])}")
        ext = os.path.splitext(final)[1].lower()
        if ext not in allowed:
            raise OutputPathError(f"{option}: unsupported file type '{ext or path}' (use {', '.join(allowed)})")
        if any(final == f for _, f, _ in self._files):
            raise OutputPathError(f"{option}: {path} is also another output of this job; give each its own file")
        folder = os.path.dirname(final)
        self._make_folder(option, folder)
        temp = os.path.join(folder, f".{os.path.basename(final)}.exsynth-{os.getpid()}-{len(self._files)}{ext}")
        try:  # the probe: can a file be created right there?
            with open(temp, "xb"):
                pass
            os.remove(temp)
        except OSError as exc:
            raise OutputPathError(f"{option}: cannot write {final} ({exc.strerror}); choose a folder you can "
                                  "write to") from None
        self._files.append((option, final, temp))
        return temp

    def commit(self):
        for option, final, temp in self._files:
            if not os.path.isfile(temp) or os.path.getsize(temp) == 0:
                raise OSError(f"{option}: nothing was written to {final} (the writer failed silently); "
                              "nothing was changed")
        for _, final, temp in self._files:
            os.replace(temp, final)
        self._files.clear()
        self._new_folders.clear()

    def discard(self):
        for _, _, temp in self._files:
            try:
                os.remove(temp)
            except OSError:
                pass
        for folder in reversed(self._new_folders):  # deepest first; only if still empty
            try:
                os.rmdir(folder)
            except OSError:
                pass
        self._files.clear()
        self._new_folders.clear()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            try:
                self.commit()
            except BaseException:
                self.discard()
                raise
        else:
            self.discard()
        return False

    def _make_folder(self, option, folder):
        missing = []
        while not os.path.isdir(folder):
            if os.path.exists(folder):
                raise OutputPathError(f"{option}: {folder} is a file, not a folder; choose another place")
            missing.append(folder)
            parent = os.path.dirname(folder)
            if parent == folder:
                break
            folder = parent
        for f in reversed(missing):
            try:
                os.mkdir(f)
            except OSError as exc:
                raise OutputPathError(f"{option}: cannot create the folder {f} ({exc.strerror}); choose a "
                                      "folder you can write to") from None
            self._new_folders.append(f)
