"""Shared by the plotting scripts: matplotlib on the Agg backend, atomic PNG output, labels
shortened (and escaped) for drawing, and one-line errors.

Exit statuses of every script: 0 drawn; 65 (sysexits' EX_DATAERR) the input data is bad
(unreadable, a missing column, a value that is not a number): the user can fix it; 70
(EX_SOFTWARE) anything else, a defect. Either way one line `SCRIPT: what failed` on stderr, no
traceback. SIGINT kills a script at once (no KeyboardInterrupt waiting for matplotlib's C code to
return); `ontime` runs the scripts on a temporary output and removes it when they are
interrupted.
"""

import csv
import json
import os
import signal
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")

BAD_INPUT_EXIT = 65
INTERNAL_ERROR_EXIT = 70

# Longest label drawn, in characters: ids and names may be a million characters long, and the
# Agg renderer fails ("raster overflow") on text far wider than any figure.
LABEL_CHARACTERS = 60
TITLE_CHARACTERS = 120

# Ids of any length are valid: lift the csv module's 128 KiB field limit.
csv.field_size_limit(sys.maxsize)

# Set on import (the scripts import this module first), not in run(): an interruption during
# matplotlib's long import must kill at once too.
signal.signal(signal.SIGINT, signal.SIG_DFL)


class BadInput(Exception):
    """The input data cannot be drawn; the message says where and why."""


def shorten(text, limit=LABEL_CHARACTERS):
    """`text` cut to at most `limit` characters, an ellipsis marking the cut."""
    text = str(text)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def label(text, limit=LABEL_CHARACTERS):
    """`text` shortened for drawing, its dollar signs escaped: matplotlib reads text between two
    of them as mathematical notation and fails on most ids that contain them."""
    return shorten(text, limit).replace("$", r"\$")


def bad_input(path, what):
    return BadInput(f"{shorten(path, 200)}: {shorten(what, 300)}")


def read_csv_rows(path, columns):
    """The rows of a CSV file as dicts; BadInput if unreadable or a column is missing."""
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            reader = csv.DictReader(handle)
            rows = list(reader)
            missing = [column for column in columns if column not in (reader.fieldnames or [])]
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise bad_input(path, error) from None
    if missing:
        raise bad_input(path, f"no column {', '.join(missing)}")
    return rows


def read_json(path):
    try:
        with open(path, encoding="utf-8") as handle:
            return json.load(handle)
    except (OSError, UnicodeDecodeError, ValueError) as error:
        raise bad_input(path, error) from None


def number(path, row_number, column, text, kind=float):
    """`text` (from `column` of data row `row_number`) as a `kind`; BadInput if it is not one."""
    try:
        return kind(text)
    except (TypeError, ValueError):
        raise bad_input(path, f"row {row_number}, column {column}: {shorten(repr(text), 40)} is not a number") from None


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


def run(main):
    """Runs main() (which returns nothing or raises) and exits with the statuses above."""
    script = os.path.basename(sys.argv[0])
    try:
        main()
    except BadInput as error:
        sys.stderr.write(f"{script}: {error}\n")
        sys.exit(BAD_INPUT_EXIT)
    except MemoryError:
        sys.stderr.write(f"{script}: internal error: out of memory while drawing\n")
        sys.exit(INTERNAL_ERROR_EXIT)
    except Exception as error:  # noqa: BLE001 -- the one place that turns any failure into one line
        message = " ".join(str(error).split())
        sys.stderr.write(f"{script}: internal error: {type(error).__name__}: {shorten(message, 300)}\n")
        sys.exit(INTERNAL_ERROR_EXIT)
    sys.exit(0)
