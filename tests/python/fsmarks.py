"""Inode marks for the tests of outputs that cannot be replaced (both tiers
import this; the Blender tier's helpers put this folder on its path)."""
import contextlib
import fcntl
import os
import struct

FS_IOC_GETFLAGS, FS_IOC_SETFLAGS = 0x80086601, 0x40086602  # linux/fs.h


@contextlib.contextmanager
def immutable(path):
    """The file marked immutable for the block (what `chattr +i` does; no chattr binary needed)."""
    fd = os.open(path, os.O_RDONLY)
    try:
        flags = struct.unpack("l", fcntl.ioctl(fd, FS_IOC_GETFLAGS, struct.pack("l", 0)))[0]
        fcntl.ioctl(fd, FS_IOC_SETFLAGS, struct.pack("l", flags | 0x10))
        try:
            yield path
        finally:
            fcntl.ioctl(fd, FS_IOC_SETFLAGS, struct.pack("l", flags))
    finally:
        os.close(fd)
