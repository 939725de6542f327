"""dyncheck/regular_files.py: a file that untrusted input names is opened only where it is a
regular file, never blocking on a FIFO, through a link only where allowed, within a size."""

from __future__ import annotations

import os

import pytest

from dyncheck.regular_files import NotRegular, Refusal, open_regular


def test_a_regular_file_is_read(tmp_path):
    path = tmp_path / "a.txt"
    path.write_bytes(b"abc")
    with open_regular(path, follow=False, most=3) as f:
        assert f.read() == b"abc"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
def test_a_fifo_is_refused_without_blocking(tmp_path):
    """A FIFO with no writer: opened for reading it would block for ever; refused at once."""
    path = tmp_path / "pipe"
    os.mkfifo(path)
    with pytest.raises(NotRegular) as caught, open_regular(path, follow=True):
        pass
    assert caught.value.refusal is Refusal.NOT_REGULAR


def test_a_link_is_followed_only_where_allowed(tmp_path):
    target = tmp_path / "t.txt"
    target.write_bytes(b"x")
    link = tmp_path / "l.txt"
    link.symlink_to(target)
    with open_regular(link, follow=True) as f:
        assert f.read() == b"x"
    with pytest.raises(NotRegular) as caught, open_regular(link, follow=False):
        pass
    assert caught.value.refusal is Refusal.UNOPENABLE


def test_a_file_over_its_size_is_refused_with_its_size(tmp_path):
    path = tmp_path / "big"
    path.write_bytes(b"0" * 10)
    with pytest.raises(NotRegular) as caught, open_regular(path, follow=False, most=9):
        pass
    assert (caught.value.refusal, caught.value.size) == (Refusal.TOO_LARGE, 10)


def test_a_missing_file_is_not_a_refusal(tmp_path):
    with pytest.raises(FileNotFoundError), open_regular(tmp_path / "none", follow=False):
        pass
