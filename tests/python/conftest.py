"""Shared fixtures of the Python module's tests: the CLI binary under test and a runner."""
import json
import os
import subprocess

import pytest

CLI = os.environ.get("RTCOST_CLI", "build/rtcost")


def run_cli(*args, check=True):
    """Runs the rtcost binary; returns the CompletedProcess (text)."""
    p = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"rtcost {' '.join(map(str, args))} exited {p.returncode}: {p.stderr}")
    return p


def cli_json(*args):
    return json.loads(run_cli(*args, "--json").stdout)


@pytest.fixture
def cli():
    return run_cli
