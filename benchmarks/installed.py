"""The installed state a user's run starts from, for the benchmarks that time whole processes.

``make setup`` writes the project's bytecode (``compileall``, scripts/setup.sh): a shell with
``PYTHONDONTWRITEBYTECODE`` set never writes it, and a module edited since the last setup is
then compiled from source on every import — inside a solve's timed region where it is imported
lazily (the beam's kernels, the envelope solver: ≈ 10 ms of fig. 5's 0.28 s). Timing that would
measure the developer's shell, not the tool.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("sandwich",)  # as scripts/setup.sh


def write_bytecode() -> None:
    """Bring the project's bytecode up to date, as ``make setup`` does (quick when it is)."""
    subprocess.run([sys.executable, "-m", "compileall", "-q", *PACKAGES], cwd=ROOT,
                   stdout=subprocess.DEVNULL, check=False)
