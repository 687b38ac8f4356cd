"""The host's side of the throwaway QEMU guest (../shared/reference/virtual-hid) that
the device tests boot: build the guest once, boot it with a script, read the script's
``RESULT {json}`` line. Used by test_hid_guest.py and test_evdev_guest.py."""

import json
import os
import shutil
import subprocess
import sys

import pytest

from conftest import ROOT, shared_folder


def guest_image():
    """``(recipe, folder)``: the recipe and the guest built from it into build/vhid (or
    $ROUGH_VHID), building it if needed; skips with the reason where it cannot be."""
    folder = type(ROOT)(os.environ.get("ROUGH_VHID") or ROOT / "build" / "vhid")
    shared = shared_folder()
    if shared is None:
        pytest.skip("../shared/reference/virtual-hid (the guest recipe) is not beside this checkout")
    recipe = shared / "reference" / "virtual-hid"
    if not (folder / "initrd.img").exists():
        if shutil.which("qemu-system-x86_64") is None:
            pytest.skip("qemu-system-x86 is not installed (.ci/run installs it)")
        if os.geteuid() != 0 or shutil.which("apt-get") is None:
            pytest.skip("building the guest needs root and apt-get (Debian's kernel and busybox packages)")
        built = subprocess.run(
            ["bash", str(recipe / "build.sh"), str(folder)], capture_output=True, text=True, timeout=1200, check=False
        )
        if built.returncode != 0 or not (folder / "initrd.img").exists():
            reason = (built.stderr or built.stdout).strip().splitlines()[-1:] or ["no output"]
            pytest.skip(f"the guest could not be built: {reason[0]}")
    return recipe, folder


def guest_python(folder):
    """This interpreter, importing the rough these tests import (the installed wheel, or
    a source tree on PYTHONPATH), as a two-line script in ``folder``: the guest's kernel
    command line carries no environment."""
    import rough

    source = os.path.dirname(os.path.dirname(os.path.abspath(rough.__file__)))
    script = folder / "python"
    script.write_text(f"#!/bin/sh\nPYTHONPATH='{source}' exec '{sys.executable}' \"$@\"\n")
    script.chmod(0o755)
    return script


def boot(image, python, script, started):
    """Boot the guest ``image`` running ``script`` (a file in tests/) with ``python``;
    returns the JSON of its last ``RESULT`` line. Skips when the guest never printed
    ``started`` (it could not boot here); fails, with the console, when it booted but
    printed no result."""
    recipe, folder = image
    console = subprocess.run(
        ["bash", str(recipe / "run.sh"), str(folder), str(python), str(ROOT / "tests" / script)],
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    lines = [
        line[line.index("RESULT {") + len("RESULT ") :] for line in console.stdout.splitlines() if "RESULT {" in line
    ]
    if not lines and started not in console.stdout:
        last = (console.stderr or console.stdout).strip().splitlines()[-1:] or ["no output"]
        pytest.skip(f"the guest could not be booted: {last[0]}")
    assert lines, f"the guest printed no result:\n{console.stdout[-3000:]}\n{console.stderr[-2000:]}"
    return json.loads(lines[-1])
