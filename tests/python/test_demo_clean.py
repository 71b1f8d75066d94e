"""The main command leaves the checkout as it found it (issue 14): `scripts/demo.sh` writes
its scenes and renders under `out/` only, and refreshing the README's images is the explicit
`scripts/demo.sh --update-docs`.

Runs the real demo (about a minute): git's view of the tree (modified, added, deleted and
untracked files that are not ignored) and the bytes of every tracked file under docs/ must be
the same before and after, and the renders must be in out/.
"""

from __future__ import annotations

import hashlib
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, check=True, capture_output=True, text=True).stdout


def _tree_state() -> tuple[str, dict[str, str]]:
    status = _git("status", "--porcelain", "--untracked-files=all")
    docs = {
        path: hashlib.sha256((ROOT / path).read_bytes()).hexdigest()
        for path in _git("ls-files", "docs").splitlines()
        if (ROOT / path).is_file()
    }
    return status, docs


def test_demo_writes_under_out_only():
    before_status, before_docs = _tree_state()
    run = subprocess.run(["scripts/demo.sh"], cwd=ROOT, capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    after_status, after_docs = _tree_state()
    assert after_status == before_status, f"the demo changed the checkout:\n{after_status}"
    changed = sorted(p for p in before_docs if after_docs.get(p) != before_docs[p])
    assert not changed, f"the demo rewrote tracked files under docs/: {changed}"
    # What it made is in out/: every image the README shows was rendered there too.
    for image in _git("ls-files", "docs/images").splitlines():
        if image.endswith(".png"):
            assert (ROOT / "out" / Path(image).name).is_file(), f"out/{Path(image).name} not rendered"
