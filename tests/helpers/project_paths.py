"""Where the tests find the project and the zoos, whatever folder a test sits in."""
from pathlib import Path

TESTS = Path(__file__).resolve().parent.parent
PROJECT_ROOT = TESTS.parent
SUBMISSIONS = TESTS / "submissions"
