"""The guest's side of the device tests (runs inside the QEMU guest, imported by
vhid_guest.py and evdev_guest.py): a scratch folder, and waiting for rough to end."""

import os
import pathlib
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent


def scratch_folder():
    """A fresh folder on a tmpfs, mounted where it hides none of the files this run
    needs (the host's root is read-only in the guest; the interpreter, rough and these
    tests may all live under /tmp, a wheel installed into a temporary environment)."""
    import rough

    needed = [
        pathlib.Path(p).resolve() for p in (sys.prefix, sys.exec_prefix, HERE, pathlib.Path(rough.__file__).parent)
    ]
    needed += [pathlib.Path(p).resolve() for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    for candidate in map(pathlib.Path, ("/media", "/srv", "/mnt", "/tmp")):
        if candidate.is_dir() and not any(candidate == n or candidate in n.parents for n in needed):
            subprocess.run(["mount", "-t", "tmpfs", "tmpfs", str(candidate)], check=True)
            folder = candidate / "rough-guest"
            folder.mkdir()
            os.chdir(folder)
            return folder
    raise SystemExit("no folder to mount a tmpfs on that hides nothing this run needs")


def ending(rough, since, timeout=30):
    """How rough ended after the device went away at ``since`` (time.monotonic):
    returncode, stderr, whether it hung (killed after ``timeout`` s) and how long it took."""
    try:
        _, err = rough.communicate(timeout=timeout)
        hung = False
    except subprocess.TimeoutExpired:
        rough.kill()
        _, err = rough.communicate()
        hung = True
    return {"returncode": rough.returncode, "stderr": err, "hung": hung, "exit_after_s": time.monotonic() - since}


def start_render(folder, device, *extra):
    """``rough render --device DEVICE`` on folder/a.x3p and folder/b.x3p as a user would
    start it, at 200 Hz (the guest is emulated), printing its JSON report."""
    command = [
        sys.executable,
        "-m",
        "rough",
        "render",
        "--device",
        device,
        "--rate",
        "200Hz",
        "--ramp",
        "0",
        "--stick-span",
        "10mm,4mm",
        "--watchdog",
        "1s",
        "--device-damping",  # a virtual device has no physics: this damping keeps the stability check quiet
        "4N*s/m",
        "--json",
        *extra,
        str(folder / "a.x3p"),
        str(folder / "b.x3p"),
    ]
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
