"""The cube-map environment-mapping autograder.

Data flows submission -> build -> worker (isolated) -> checks -> score ->
reports; each step is a module or package of the same name.
"""
from pathlib import Path

PROJECT_ROOT = Path(__file__).resolve().parent.parent
