"""Copies, bundles and the kit's digest list leave build outputs out, never
the grader's build package: grader/build/ shares the name of the folders
`make` fills, and a rule by name alone dropped it from autograder.zip."""
from __future__ import annotations

from grader import PROJECT_ROOT, in_build_output


def test_build_outputs_are_told_from_the_build_package():
    assert in_build_output(("build", "libenvmap.so"))
    assert in_build_output(("selfcheck", "build", "libenvmap.so"))
    assert in_build_output(("student_template", "build", "envmap.o"))
    assert not in_build_output(("grader", "build", "__init__.py"))
    assert not in_build_output(("grader", "build", "shim", "shim.cpp"))
    assert not in_build_output(("selfcheck", "grader", "build", "objects.py"))
    assert not in_build_output(("build",))          # a file named build is not a folder of outputs


def test_autograder_zip_holds_the_build_package_and_no_build_output():
    from grader.platforms.gradescope import _files
    shipped = {f.relative_to(PROJECT_ROOT).as_posix() for f in _files()}
    package = {p.relative_to(PROJECT_ROOT).as_posix() for p in (PROJECT_ROOT / "grader" / "build").rglob("*")
               if p.is_file() and "__pycache__" not in p.parts}
    assert package and package <= shipped, sorted(package - shipped)
    assert not [f for f in shipped if f.startswith("build/")]


def test_the_kits_digest_list_covers_its_build_package(tmp_path):
    from grader.kit.integrity import _files
    for rel in ("grader/build/__init__.py", "grader/build/shim/shim.cpp", "build/libenvmap.so", "grader/x.py"):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(rel)
    assert sorted(_files(tmp_path)) == ["grader/build/__init__.py", "grader/build/shim/shim.cpp", "grader/x.py"]
