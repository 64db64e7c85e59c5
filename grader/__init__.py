"""The cube-map environment-mapping autograder.

Data flows intake -> build -> worker (isolated) -> checks -> grading ->
reports, each step a module or package of that name; envmap/ is the
reference C library's Python face, i18n/ the languages (docs/ARCHITECTURE.md).
"""
from pathlib import Path

PROJECT_ROOT = Path(__file__).resolve().parent.parent
# Real HDR probes (../shared/probes beside the checkout, see its PROVENANCE.md):
# tests and benchmarks read them when present; the project never copies them.
PROBES = PROJECT_ROOT.parent / "shared" / "probes"
# The build step is the package grader/build/; every other folder named build
# (the project's, a kit's, the template's) holds build outputs, which copies,
# bundles and digest lists leave out.
BUILD_PACKAGE = ("grader", "build")


def in_build_output(parts: tuple[str, ...]) -> bool:
    """Whether a file (its path's parts, from a project's or a kit's root)
    lies in a build-output folder."""
    return any(part == "build" and parts[max(0, i - 1):i + 1] != BUILD_PACKAGE for i, part in enumerate(parts[:-1]))
