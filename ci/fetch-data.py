#!/usr/bin/env python3
"""Fetch the test and example data into VIEWSYNTH_DATA_DIR (default: ../shared/data beside the
repository) and check every file's SHA-256 against ci/data-sources.txt.

Sources: each file's pinned public URL (GitHub raw at a fixed commit or tag), or, with
VIEWSYNTH_DATA_MIRROR set to a folder or a file:// URL, the same path under that mirror (no
network). Files already in place with the right digest are kept. The fetched files are staged
beside the data folder and moved in only once every one has been verified, so a failed run
leaves the data folder as it was.

    python3 ci/fetch-data.py                 # fetch what is missing, verify all
    python3 ci/fetch-data.py --check         # verify the data folder only, fetch nothing
    VIEWSYNTH_DATA_MIRROR=/mnt/data python3 ci/fetch-data.py --dest /tmp/data

Exit status: 0 all verified, 1 a file missing at its source, unreadable or with another digest,
2 a usage error (a bad option, or a mirror that is not a folder).

Python's standard library only (hashlib, urllib), so that a fresh clone needs nothing installed
beyond python3, which CI has already.
"""

import argparse
import hashlib
import os
import shutil
import sys
import tempfile
import urllib.parse
import urllib.request
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
SOURCES = REPO / "ci" / "data-sources.txt"
TIMEOUT_S = 60


class FetchError(Exception):
    """A file could not be fetched or did not verify (exit 1)."""


def read_sources(path):
    """[(sha256, relative path, url)] from the sources list; blank lines and # comments skipped."""
    entries = []
    for n, line in enumerate(path.read_text().splitlines(), 1):
        if not line.strip() or line.startswith("#"):
            continue
        fields = line.split()
        if len(fields) != 3 or len(fields[0]) != 64:
            raise SystemExit(f"fetch-data: {path}:{n}: expected 'SHA256  PATH  URL'")
        digest, rel, url = fields
        if Path(rel).is_absolute() or ".." in Path(rel).parts:
            raise SystemExit(f"fetch-data: {path}:{n}: {rel} is not a path inside the data folder")
        entries.append((digest, rel, url))
    return entries


def mirror_folder(value):
    """VIEWSYNTH_DATA_MIRROR as a folder: a path, or a file:// URL."""
    if value.startswith("file:"):
        value = urllib.request.url2pathname(urllib.parse.urlparse(value).path)
    folder = Path(value)
    if not folder.is_dir():
        print(f"fetch-data: VIEWSYNTH_DATA_MIRROR: {value} is not a folder", file=sys.stderr)
        sys.exit(2)
    return folder


def sha256_of(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def fetch_one(rel, url, mirror, to):
    """Copy `rel` from the mirror, or download `url`, into the file `to`."""
    if mirror is not None:
        src = mirror / rel
        if not src.is_file():
            raise FetchError(f"{rel}: not in the mirror ({src})")
        shutil.copyfile(src, to)
        return
    try:
        with urllib.request.urlopen(url, timeout=TIMEOUT_S) as r, open(to, "wb") as f:
            shutil.copyfileobj(r, f)
    except OSError as e:  # URLError and HTTPError are OSErrors
        raise FetchError(f"{rel}: download of {url} failed: {e}") from e


def verify(rel, path, want):
    got = sha256_of(path)
    if got != want:
        raise FetchError(f"{rel}: SHA-256 {got}, expected {want}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--dest", type=Path, help="data folder (VIEWSYNTH_DATA_DIR, else ../shared/data)")
    p.add_argument("--check", action="store_true", help="verify the data folder only; fetch nothing")
    args = p.parse_args()
    dest = args.dest or Path(os.environ.get("VIEWSYNTH_DATA_DIR") or REPO.parent / "shared" / "data")
    mirror_env = os.environ.get("VIEWSYNTH_DATA_MIRROR")
    mirror = mirror_folder(mirror_env) if mirror_env else None
    entries = read_sources(SOURCES)

    missing = []
    failures = []
    for want, rel, url in entries:
        path = dest / rel
        if path.is_file() and sha256_of(path) == want:
            continue
        if args.check:
            failures.append(f"{rel}: " + ("SHA-256 differs" if path.exists() else "missing"))
        else:
            missing.append((want, rel, url))
    if args.check:
        for f in failures:
            print(f"fetch-data: {f}", file=sys.stderr)
        if failures:
            print(f"fetch-data: {len(failures)} of {len(entries)} files wrong in {dest}; "
                  "run python3 ci/fetch-data.py to fetch them", file=sys.stderr)
            return 1
        print(f"fetch-data: {len(entries)} files verified in {dest}")
        return 0

    source = f"mirror {mirror}" if mirror else "the pinned URLs"
    if missing:
        dest.mkdir(parents=True, exist_ok=True)
        stage = Path(tempfile.mkdtemp(prefix=".fetch-", dir=dest))
        try:
            for want, rel, url in missing:
                staged = stage / rel
                staged.parent.mkdir(parents=True, exist_ok=True)
                fetch_one(rel, url, mirror, staged)
                verify(rel, staged, want)
            for _, rel, _ in missing:
                (dest / rel).parent.mkdir(parents=True, exist_ok=True)
                os.replace(stage / rel, dest / rel)
        except FetchError as e:
            print(f"fetch-data: FAILED: {e} (from {source}); nothing written to {dest}", file=sys.stderr)
            return 1
        finally:
            shutil.rmtree(stage, ignore_errors=True)
    print(f"fetch-data: {len(entries)} files verified in {dest} "
          f"({len(missing)} fetched from {source}, {len(entries) - len(missing)} already there)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
