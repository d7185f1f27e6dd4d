"""Shared by the plotting scripts: matplotlib on the Agg backend and atomic PNG output."""

import os
import tempfile

import matplotlib

matplotlib.use("Agg")


def save_atomically(figure, path, dpi=110):
    """Writes the figure to a temporary PNG beside `path`, then renames it over `path`."""
    directory = os.path.dirname(os.path.abspath(path))
    handle, temporary = tempfile.mkstemp(prefix=".plot-", suffix=".png", dir=directory)
    os.close(handle)
    try:
        figure.savefig(temporary, dpi=dpi)
        os.chmod(temporary, 0o644)
        os.replace(temporary, path)
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)
