"""The face table is written once (reference/src/lookup.c); its text,
grader.envmap.geometry.face_uv_formulas(), is what every document prints and
what the figures label, and it says what the independent model says."""
import re

import numpy as np
import pytest

import assignment_model as model
from grader.cubemap import figures
from grader.envmap import geometry
from project_paths import PROJECT_ROOT

# The statement of the assignment and the student README in every language.
DOCUMENTS = ("docs/assignment.md",
             *sorted(p.relative_to(PROJECT_ROOT).as_posix() for p in (PROJECT_ROOT / "student_template").glob("README*.md")))
FACE_ROW = re.compile(r"^\| [+-][XYZ] \|")


@pytest.mark.parametrize("document", DOCUMENTS)
def test_each_documents_table_is_the_generated_one(document):
    assert len(DOCUMENTS) >= 3
    rows = [line.rstrip() for line in (PROJECT_ROOT / document).read_text(encoding="utf-8").splitlines()
            if FACE_ROW.match(line)]
    expected = geometry.face_table_rows()
    assert rows == expected, f"{document}'s face table should read:\n" + "\n".join(expected)


def test_the_figures_label_faces_with_the_generated_formulas():
    assert figures.UV_FORMULAS == geometry.face_uv_formulas()


def _evaluate(formula: str, dirs: np.ndarray) -> np.ndarray:
    """A formula "(1 + z/m)/2" of the table, on directions (n, 3) that touch its face."""
    sign, axis = re.fullmatch(r"\(1 ([+-]) ([xyz])/m\)/2", formula).groups()
    m = np.abs(dirs).max(axis=1)
    component = dirs[:, "xyz".index(axis)] / m
    return (1 + component) / 2 if sign == "+" else (1 - component) / 2


@pytest.mark.parametrize("face", range(6))
def test_the_generated_formulas_are_the_handouts(face, rng):
    """Read as arithmetic, the words give the model's (u, v): the wording, not
    only the frames it is made from, is right."""
    dirs = rng.normal(size=(500, 3))
    dirs = dirs[model.touching_faces(dirs)[:, face]]
    fu, fv = geometry.face_uv_formulas()[model.FACE_NAMES[face]]
    mu, mv = model.face_uv(dirs, face)
    np.testing.assert_allclose(_evaluate(fu, dirs), mu, atol=1e-15)
    np.testing.assert_allclose(_evaluate(fv, dirs), mv, atol=1e-15)


def test_the_catalogues_examples_quote_the_table():
    """The u-flipped and v-flipped explanations quote rows of the table
    ("`(1 + z/m)/2` on +X"): each quote is that face's formula."""
    from grader.grading.catalogue import CATALOGUE
    formulas = geometry.face_uv_formulas()
    quotes = [(formula, face, info.id) for info in CATALOGUE.values()
              for formula, face in re.findall(r"`(\(1 [+-] [xyz]/m\)/2)` on ([+-][XYZ])", info.explanation_id)]
    assert {q[2] for q in quotes} == {"u-flipped", "v-flipped"}
    for formula, face, diagnosis in quotes:
        assert formula in formulas[face], f"{diagnosis} quotes {formula} on {face}; the table has {formulas[face]}"


def test_lookup_c_comments_its_table_with_the_generated_formulas():
    """lookup.c's FACE_AXES rows carry the formulas as comments: they say what the row does."""
    source = (PROJECT_ROOT / "reference" / "src" / "lookup.c").read_text()
    formula = r"\(1 [+-] [xyz]/m\)/2"
    comments = re.findall(rf"/\* ([+-][XYZ]): u = ({formula}), v = ({formula}) \*/", source)
    assert {face: (u, v) for face, u, v in comments} == geometry.face_uv_formulas()
