"""The cube-map environment-mapping autograder.

Data flows submission -> build -> worker (isolated) -> checks -> score ->
reports; each step is a module or package of the same name.
"""
from pathlib import Path

PROJECT_ROOT = Path(__file__).resolve().parent.parent
# Real HDR probes (../shared/probes beside the checkout, see its PROVENANCE.md):
# tests and benchmarks read them when present; the project never copies them.
PROBES = PROJECT_ROOT.parent / "shared" / "probes"
