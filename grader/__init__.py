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
