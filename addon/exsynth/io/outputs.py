# SPDX-License-Identifier: GPL-3.0-or-later
"""The files one job writes: all of them, or none.

Every output path is checked when it is declared, before the job starts (a
folder given as a file, a folder that cannot be written, a wrong extension),
by creating and removing a probe file next to it; an existing file there
that cannot be replaced (immutable or append-only) is refused then too.
Writers write to a temporary name in the same folder; `commit()` checks that
each file was really written (Blender's exporters fail silently on some
paths), moves the existing files aside, renames the new ones into place and
only then deletes the old ones; if any rename fails, every step is undone. A
failed, cancelled or interrupted job leaves no new file, and the existing
files at its output paths as they were.

No bpy here: the CLI and the tests use it alike.
"""

import errno
import fcntl
import os
import struct

_FS_IOC_GETFLAGS = 0x80086601  # linux/fs.h: the inode flags chattr sets
_IMMUTABLE, _APPEND_ONLY = 0x10, 0x20


class OutputPathError(ValueError):
    """An output path cannot be written; the message names the option."""


class OutputFiles:
    """Use as a context manager: the files are committed when the block ends
    normally and discarded when it raises (KeyboardInterrupt included)."""

    def __init__(self):
        self._files = []  # (option, final path, temporary path, the path as given)
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
        if any(final == f for _, f, _, _ in self._files):
            raise OutputPathError(f"{option}: {path} is also another output of this job; give each its own file")
        if os.path.lexists(final) and _locked(final):
            raise OutputPathError(f"{option}: {path} exists and cannot be replaced (it is marked immutable or "
                                  "append-only, see lsattr); choose another name or clear the mark (chattr -i)")
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
        self._files.append((option, final, temp, path))
        return temp

    def commit(self):
        for option, _, temp, given in self._files:
            if not os.path.isfile(temp) or os.path.getsize(temp) == 0:
                raise OSError(f"{option}: nothing was written to {given} (the writer failed silently); "
                              "nothing was changed")
        moved, placed = [], []  # (final, its old file moved aside); finals renamed into place
        try:
            for option, final, temp, given in self._files:
                step = "replace"
                if os.path.isdir(final) and not os.path.islink(final):  # made while the job ran
                    raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR))
                if os.path.lexists(final):
                    os.rename(final, temp + ".old")
                    moved.append((final, temp + ".old"))
                step = "write"
                os.rename(temp, final)
                placed.append(final)
        except OSError as exc:
            for final in placed:
                os.remove(final)
            for final, old in reversed(moved):
                os.rename(old, final)
            raise OSError(f"{option}: cannot {step} {given} ({exc.strerror}); choose another name") from None
        for _, old in moved:
            os.remove(old)
        self._files.clear()
        self._new_folders.clear()

    def discard(self):
        for _, _, temp, _ in self._files:
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


def _locked(path):
    """True if the file is immutable or append-only (a rename over it fails)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOFOLLOW)
    except OSError:
        return False
    try:
        flags = struct.unpack("l", fcntl.ioctl(fd, _FS_IOC_GETFLAGS, struct.pack("l", 0)))[0]
    except OSError:  # the filesystem has no such flags
        return False
    finally:
        os.close(fd)
    return bool(flags & (_IMMUTABLE | _APPEND_ONLY))
