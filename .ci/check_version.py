"""The versioning rule of CHANGELOG.md, checked: the package version is the newest
CHANGELOG entry, and no commit since the one that set the version has changed the
package (rough/, setup.cfg) unless it is a formatting-only commit listed in
.git-blame-ignore-revs or says in its message why behaviour is unchanged
("Version-unchanged: <reason>"). Exit status 1 with the reason when the rule is broken.
"""

import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
PACKAGE_PATHS = ("rough", "setup.cfg")
TRAILER = "Version-unchanged:"


def package_version():
    text = (ROOT / "rough" / "__init__.py").read_text()
    return re.search(r'^__version__ = "([^"]+)"$', text, re.MULTILINE)[1]


def changelog_version():
    match = re.search(r"^## \[?(\d+\.\d+\.\d+[^\]\s]*)\]?", (ROOT / "CHANGELOG.md").read_text(), re.MULTILINE)
    return match[1] if match else None


def git(*args):
    return subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, text=True, check=True).stdout


def unexplained_changes():
    """Commits after the one that set the version that touch the package without saying why
    the version stays; None where the history is not available."""
    try:
        if git("rev-parse", "--is-shallow-repository").strip() == "true":
            return None
        setter = git("log", "-1", "--format=%H", "-G", r"^__version__ = ", "--", "rough/__init__.py").strip()
    except (OSError, subprocess.CalledProcessError):
        return None
    ignored = set(re.findall(r"^[0-9a-f]{40}$", (ROOT / ".git-blame-ignore-revs").read_text(), re.MULTILINE))
    since = git("log", "--format=%H", f"{setter}..HEAD", "--", *PACKAGE_PATHS).split()
    return setter, [c for c in since if c not in ignored and TRAILER not in git("log", "-1", "--format=%B", c)]


def main():
    version, listed = package_version(), changelog_version()
    if version != listed:
        sys.exit(f"version check: rough/__init__.py says {version} but the newest CHANGELOG.md entry is {listed}")
    found = unexplained_changes()
    if found is None:
        print(f"version check: {version} matches CHANGELOG.md (no git history here: commits not checked)")
        return
    setter, changes = found
    if changes:
        listing = ", ".join(c[:8] for c in changes)
        sys.exit(
            f"version check: {len(changes)} commit(s) changed the package after the version was last set "
            f"in {setter[:8]} ({listing}); bump __version__ and add a CHANGELOG.md entry, "
            f"or say '{TRAILER} <why>' in the commit message (see CHANGELOG.md, 'Versioning')"
        )
    print(f"version check: {version} matches CHANGELOG.md and covers every change of the package")


if __name__ == "__main__":
    main()
