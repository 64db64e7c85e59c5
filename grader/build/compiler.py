"""Privilege-drop mode: the compiler's uid can read nothing of ours.

Where bubblewrap cannot run (Gradescope, PrairieLearn: containers without
user namespaces; mount namespaces need CAP_SYS_ADMIN), the student's
preprocessor, compiler, assembler and linker run as BUILD_UID in a scratch
folder of their own (grader/build/__init__.py). What keeps the grader's and the
course's files from them is the file permissions: before the first such
build, a probe running as BUILD_UID tries each sentinel (the rubric, the
reference's lookup.c and library, the fixtures, the upload, the build
cache, Gradescope's /autograder and PrairieLearn's /grade and what they
hold). The folders the grader owns are fixed (`chmod o-rwx`: root, which
grades, keeps every access; nothing else the grader runs needs them: the
worker enters its chroot as root). If the probe still reads anything,
building raises BuildConfinementError and nothing of the student's is
compiled.

What BUILD_UID can read then is what any uid can: the system (/usr, /etc's
public files), world-readable folders such as /tmp (where only the scratch
folder, mode 0700 and its own, holds anything of ours) and its scratch
folder's copies of the source, the API headers and our objects.
"""
from __future__ import annotations

import functools
import os
import stat
import subprocess
from pathlib import Path

from .. import PROJECT_ROOT
from . import BUILD_GID, BUILD_UID, HarnessBuildError

# Gradescope's and PrairieLearn's roots (tests lay them out elsewhere and
# say so in the variables run_autograder and prairielearn.sh read).
PLATFORM_ROOTS = ("/autograder", "/grade")
PLATFORM_ROOT_VARIABLES = ("AUTOGRADER_ROOT", "PL_GRADE_ROOT")
# What each platform root holds that is not the student's to read.
PLATFORM_SENTINELS = ("source", "submission", "submission_metadata.json", "results",
                      "tests", "serverFilesCourse", "student", "data")
PROJECT_SENTINELS = ("grader/grading/rubric.toml", "reference/src/lookup.c", "build/libenvmap.so",
                     "fixtures/manifest.json", "grader", "reference", "build")

# Prints each argument the calling uid can read, or enter if a folder.
_PROBE = ('for p do if [ -r "$p" ] || { [ -d "$p" ] && [ -x "$p" ]; }; then printf "%s\\n" "$p"; fi; done')


class BuildConfinementError(HarnessBuildError):
    """The build uid can read the grader's or the course's files: grading
    would let a submission's compiler quote them. For the instructor."""


def platform_roots() -> list[Path]:
    roots = [Path(p) for p in PLATFORM_ROOTS]
    roots += [Path(os.environ[v]) for v in PLATFORM_ROOT_VARIABLES if os.environ.get(v)]
    return [r for r in dict.fromkeys(roots) if os.path.lexists(r)]


def confined_roots(upload: Path | None, cache_dir: Path | None) -> list[Path]:
    """The folders (and upload) the build uid must not enter, that exist."""
    roots = [PROJECT_ROOT, *platform_roots()]
    roots += [p for p in (cache_dir, upload) if p is not None]
    return [Path(os.path.realpath(r)) for r in dict.fromkeys(roots) if os.path.lexists(r)]


def sentinels(upload: Path | None, cache_dir: Path | None) -> list[Path]:
    """Files and folders the build uid must not read: the roots, and inside
    them what a compiler could quote."""
    found = confined_roots(upload, cache_dir)
    found += [PROJECT_ROOT / name for name in PROJECT_SENTINELS]
    found += [root / name for root in platform_roots() for name in PLATFORM_SENTINELS]
    if upload is not None and os.path.isdir(upload) and not os.path.islink(upload):
        found += [Path(upload) / name for name in sorted(os.listdir(upload))[:100]]
    return [p for p in dict.fromkeys(found) if os.path.lexists(p)]


def readable_by(uid: int, gid: int, paths: list[Path]) -> list[Path]:
    """Which of `paths` a process of uid/gid (no supplementary groups) can
    read or, for a folder, enter: asked of the kernel by a shell running as
    that uid."""
    if not paths:
        return []
    done = subprocess.run(["/bin/sh", "-c", _PROBE, "sh", *map(str, paths)], capture_output=True,
                          stdin=subprocess.DEVNULL, user=uid, group=gid, extra_groups=[],
                          env={"PATH": "/usr/bin:/bin"}, cwd="/", timeout=60)
    return [Path(line) for line in done.stdout.decode("utf-8", "surrogateescape").splitlines() if line]


def _close(root: Path) -> None:
    """chmod o-rwx (and g-rwx when the group is the build gid) on one of our folders or the upload."""
    info = os.lstat(root)
    if stat.S_ISLNK(info.st_mode):
        return
    mode = stat.S_IMODE(info.st_mode) & ~0o007
    if info.st_gid == BUILD_GID:
        mode &= ~0o070
    try:
        os.chmod(root, mode)
    except OSError:
        pass  # e.g. a read-only file system: the second probe says what is still readable


@functools.lru_cache(maxsize=None)
def _ensured(roots: tuple[Path, ...], probes: tuple[Path, ...]) -> None:
    open_ = readable_by(BUILD_UID, BUILD_GID, list(probes))
    if not open_:
        return
    for root in roots:
        _close(root)
    still = readable_by(BUILD_UID, BUILD_GID, list(probes))
    if still:
        shown = ", ".join(str(p) for p in still[:5]) + (f" and {len(still) - 5} more" if len(still) > 5 else "")
        raise BuildConfinementError(
            f"privilege-drop mode: the compiler's uid {BUILD_UID} can still read {shown} after "
            f"chmod o-rwx on {', '.join(map(str, roots))}. A submission's compiler could quote these files "
            "to the student, so nothing is built. Make them unreadable to other users (for example "
            "chmod o-rwx on the folder that holds them, or a parent), or grade where bubblewrap runs "
            "(docs/security.md, Build).")


def ensure_confined(upload: Path | None, cache_dir: Path | None) -> None:
    """Before a privilege-drop build: make the build uid unable to read the
    grader's, the course's and the uploads' files, or raise
    BuildConfinementError. Checked once per set of paths and process."""
    _ensured(tuple(confined_roots(upload, cache_dir)), tuple(sentinels(upload, cache_dir)))


def readable_tree(uid: int, gid: int, roots: list[Path]) -> list[Path]:
    """Every file and folder under `roots` a process of uid/gid can read or
    enter (find as that uid): what it can see, listed."""
    done = subprocess.run(["find", *map(str, roots), "(", "-readable", "-o", "-type", "d", "-executable", ")",
                           "-print"], capture_output=True, stdin=subprocess.DEVNULL, user=uid, group=gid,
                          extra_groups=[], env={"PATH": "/usr/bin:/bin"}, cwd="/", timeout=300)
    return [Path(line) for line in done.stdout.decode("utf-8", "surrogateescape").splitlines() if line]
