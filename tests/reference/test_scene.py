"""The scene-file reader (reference/src/scene.c): every syntax element, every
error with its file and line, defaults, and relative file names.

What the parser stores beyond size, map path and hdr_gamma is only visible
through tracing, so equivalences are checked as "both texts trace to the same
escapes" (trace is deterministic, tests/reference/test_render.py)."""
from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest

from grader import PROJECT_ROOT
from grader.envmap.library import EnvmapError, Scene

ENV = 'environment_light { filename = "map.hdr"; }\n'
EM_ERR_IO, EM_ERR_TOO_LARGE, EM_ERR_SCENE = -1, -4, -8


def traced(text: str, name: str = "t.cfg"):
    """The escapes of a small render of text, as a tuple of arrays."""
    scene = Scene.parse(text, name)
    scene.set_resolution(6, 4)
    scene.set_samples(4)
    e = scene.trace()
    return e.dirs, e.weights, e.pixels


def same_scene(a: str, b: str) -> bool:
    return all(np.array_equal(x, y) for x, y in zip(traced(a), traced(b)))


SPHERES = """
camera { position = (0, 0.5, 4); look_at = (0, 0, 0); up = (0, 1, 0); fov = 50; }
sampling { samples_per_pixel = 4; max_depth = 5; seed = 3; }
sphere { center = (-1, 0, 0); radius = 0.8; material = "mirror"; tint = (1, 0.5, 0.25); }
sphere { center = (1, 0, 0); radius = 0.8; material = "glass"; ior = 1.4; }
""" + ENV


# ---- syntax --------------------------------------------------------------------

def test_a_minimal_scene_has_the_documented_defaults():
    scene = Scene.parse(ENV, "t.cfg", "")
    assert (scene.width, scene.height) == (512, 512)
    assert scene.hdr_gamma == 1.0
    assert scene.environment_path == Path("map.hdr")
    explicit = """
    camera { position = (0, 0, 0); look_at = (0, 0, -1); up = (0, 1, 0); fov = 45; width = 512; height = 512; }
    sampling { samples_per_pixel = 16; max_depth = 32; seed = 0; }
    sphere { center = (0, 0, -3); radius = 1; material = "glass"; ior = 1.5; tint = (1, 1, 1); }
    environment_light { filename = "map.hdr"; hdr_gamma = 1.0; }
    """
    implicit = 'sphere { center = (0, 0, -3); radius = 1; material = "glass"; }\n' + ENV
    assert same_scene(explicit, implicit)


def test_the_default_max_depth_is_32():
    """Inside a glass ball, just under the critical angle, paths reflect
    inside with F close to 1, so every extra bounce adds an escape."""
    inside = """camera { position = (0, 1.333, 0); look_at = (0, 1.333, -1); fov = 1; }
    sphere { center = (0, 0, 0); radius = 2; material = "glass"; }\n""" + ENV
    depth = [inside.replace("camera {", f"sampling {{ max_depth = {d}; }}\ncamera {{") for d in (31, 32, 33)]
    assert same_scene(inside, depth[1])
    assert not same_scene(inside, depth[0]) and not same_scene(inside, depth[2])


def test_tuples_with_commas_and_bare_number_lists_are_the_same():
    bare = SPHERES.replace("(", "").replace(")", "").replace(",", "")
    assert "0 0.5 4" in bare
    assert same_scene(SPHERES, bare)


def test_comments_and_layout_do_not_change_the_scene():
    commented = """// a line comment
    /* a block comment
       over lines { with = "braces"; } */
    camera
    {
        position = (0, 0.5, 4);   // after a value
        look_at=(0,0,0);up=(0,1,0);fov=50;
    }
    sampling { samples_per_pixel = 4; /* inline */ max_depth = 5; seed = 3; }
    sphere { center = (-1, 0, 0); radius = 0.8; material = "mirror"; tint = (1, 0.5, 0.25); }
    sphere { center = (1, 0, 0); radius = .8; material = "glass"; ior = 14e-1; }
    environment_light { filename = "map.hdr"; }  // the end"""
    assert same_scene(SPHERES, commented)


def test_every_key_changes_the_scene():
    """Each key is read, not silently dropped: changing its value changes the trace."""
    changes = [
        ("position = (0, 0.5, 4)", "position = (0, 0.6, 4)"),
        ("look_at = (0, 0, 0)", "look_at = (0, 0.1, 0)"),
        ("up = (0, 1, 0)", "up = (0.2, 1, 0)"),
        ("fov = 50", "fov = 40"),
        ("max_depth = 5", "max_depth = 1"),
        ("seed = 3", "seed = 4"),
        ("center = (-1, 0, 0)", "center = (-1.1, 0, 0)"),
        ("radius = 0.8", "radius = 0.7"),
        ('material = "mirror"', 'material = "glass"'),
        ("ior = 1.4", "ior = 1.6"),
        ("tint = (1, 0.5, 0.25)", "tint = (1, 0.5, 0.5)"),
    ]
    for old, new in changes:
        assert old in SPHERES
        assert not same_scene(SPHERES, SPHERES.replace(old, new, 1)), old


def test_samples_per_pixel_and_size_are_read():
    scene = Scene.parse("camera { width = 7; height = 3; }\nsampling { samples_per_pixel = 5; }\n" + ENV)
    assert (scene.width, scene.height) == (7, 3)
    # No spheres: every sample escapes once.
    assert len(scene.trace().dirs) == 7 * 3 * 5


def test_hdr_gamma_and_filename_are_read():
    scene = Scene.parse('environment_light { filename = "/maps/a b.hdr"; hdr_gamma = 2.2; }', "t.cfg", "/x")
    assert scene.hdr_gamma == 2.2
    assert scene.environment_path == Path("/maps/a b.hdr")


def test_the_handouts_block_reads_as_written():
    """The environment_light block as printed in the handout (handout_ja.txt)."""
    text = """/* ... */

environment_light
{
// filename = "Cubemap/beach_cross.hdr";
// filename = "Cubemap/uffizi_cross.hdr";
filename = "Cubemap/test_environment_map.hdr";
    hdr_gamma = 1.0;
}

/* ... */
"""
    scene = Scene.parse(text, "envmap_test.cfg", "/course")
    assert scene.environment_path == Path("/course/Cubemap/test_environment_map.hdr")


# ---- errors -------------------------------------------------------------------

SPHERE_OK = 'sphere { center = (0, 0, 0); radius = 1; material = "mirror"; }\n'

ERRORS = [
    ("sphere {\n  center = (0, 0, 0);\n  radus = 1;\n}\n" + ENV, "t.cfg:3: unknown key 'radus' in sphere"),
    ("spere { }\n" + ENV, "t.cfg:1: unknown block 'spere'"),
    ("camera { fov = 40 }\n" + ENV, "t.cfg:1: expected ';', got '}'"),
    ("camera {\n fov = 40;\n", "t.cfg:3: end of file inside camera block (opened at line 1)"),
    ('environment_light { filename = "a.hdr; }\n', "t.cfg:1: unterminated string"),
    ("\n/* never closed\n\n" + ENV, "t.cfg:2: unterminated /* comment"),
    ("camera { fov = 40; fov = 41; }\n" + ENV, "t.cfg:1: 'fov' set twice in camera (first at line 1)"),
    ("camera { }\n\ncamera { }\n" + ENV, "t.cfg:3: second camera block (the first is at line 1)"),
    ("camera { position = (0, 1); }\n" + ENV, "t.cfg:1: 'position' in camera expects 3 numbers, got 2"),
    ("camera { position = 0 1 2 3; }\n" + ENV, "t.cfg:1: 'position' in camera expects 3 numbers, got 4"),
    ("camera { fov = 1 2 3 4 5; }\n" + ENV, "t.cfg:1: too many numbers in one value"),
    ('camera { fov = "40"; }\n' + ENV, "t.cfg:1: 'fov' in camera expects a number, not a string"),
    ("environment_light { filename = 3; }\n", "t.cfg:1: 'filename' in environment_light expects a \"string\""),
    ('environment_light { filename = ""; }\n', "t.cfg:1: 'filename' in environment_light is empty"),
    ("camera { fov = 180; }\n" + ENV, "t.cfg:1: 'fov' in camera must be in (0, 180), got 180"),
    ("camera { width = 0; }\n" + ENV, "t.cfg:1: 'width' in camera must be in [1, 16384], got 0"),
    ("camera { width = 10.5; }\n" + ENV, "t.cfg:1: 'width' in camera must be a whole number, got 10.5"),
    ("sampling { samples_per_pixel = 0; }\n" + ENV, "t.cfg:1: 'samples_per_pixel' in sampling must be in [1, 4096], got 0"),
    ("sampling { max_depth = -1; }\n" + ENV, "t.cfg:1: 'max_depth' in sampling must be in [0, 64], got -1"),
    ("sphere { center = 0 0 0; radius = -1; }\n" + ENV, "t.cfg:1: 'radius' in sphere must be > 0, got -1"),
    ('environment_light { filename = "a"; hdr_gamma = 0; }\n', "t.cfg:1: 'hdr_gamma' in environment_light must be > 0, got 0"),
    ('sphere { material = "metal"; }\n' + ENV, 't.cfg:1: unknown material "metal" (expected "mirror" or "glass")'),
    ("sphere { material = mirror; }\n" + ENV, "t.cfg:1: expected a value (a number, a tuple or a \"string\"), got 'mirror'"),
    ("sphere {\n center = (0, 0, 0);\n material = \"glass\";\n}\n" + ENV, "t.cfg:1: sphere has no 'radius'"),
    ('sphere {\n center = 0 0 0;\n radius = 1;\n ior = 1.5;\n material = "mirror";\n}\n' + ENV,
     "t.cfg:4: 'ior' applies to material \"glass\" only"),
    ("sphere { center = 0 0 0; radius = 1; material = \"mirror\"; tint = (1, -1, 1); }\n" + ENV,
     "t.cfg:1: 'tint' in sphere must not be negative"),
    ("environment_light { hdr_gamma = 1; }\n", "t.cfg:1: environment_light has no 'filename'"),
    (SPHERE_OK + "\n", "t.cfg:3: no environment_light block"),
    ("camera { fov = 1.5.2; }\n" + ENV, "t.cfg:1: malformed number '1.5.'"),
    ("camera { fov = 3x; }\n" + ENV, "t.cfg:1: malformed number '3x'"),
    ("camera { fov = 1e999; }\n" + ENV, "t.cfg:1: number '1e999' out of range"),
    ("camera { position = (0 1 2); }\n" + ENV, "t.cfg:1: expected ',', got number 1"),
    ("camera { position = (0, 1, 2; }\n" + ENV, "t.cfg:1: expected ',', got ';'"),
    ("camera { fov = 40 @ }\n" + ENV, "t.cfg:1: unexpected character '@'"),
    ("camera { fov = \x0040; }\n" + ENV, "t.cfg:1: unexpected byte 0x00"),
    ("= 3;\n" + ENV, "t.cfg:1: expected a block name, got '='"),
    ("camera fov = 40;\n" + ENV, "t.cfg:1: expected '{', got 'fov'"),
    ("camera { 40; }\n" + ENV, "t.cfg:1: expected a key or '}', got number 40"),
    ("camera { fov 40; }\n" + ENV, "t.cfg:1: expected '=', got number 40"),
    ("camera { position = (1, 2, 3); look_at = 1 2 3; }\n" + ENV, "t.cfg:1: camera look_at equals its position"),
    ("camera {\n look_at = 0 5 0;\n up = 0 1 0;\n}\n" + ENV,
     "t.cfg:1: camera up is zero or parallel to the view direction"),
]


@pytest.mark.parametrize("text, message", ERRORS, ids=[m.split(": ", 1)[1][:40] for _, m in ERRORS])
def test_errors_name_the_file_and_line(text, message):
    with pytest.raises(EnvmapError) as info:
        Scene.parse(text, "t.cfg")
    assert str(info.value) == message
    assert info.value.code == EM_ERR_SCENE


def test_lines_are_counted_through_block_comments():
    text = "/* one\ntwo\nthree */ camera {\n\n  bogus = 1;\n}\n" + ENV
    with pytest.raises(EnvmapError, match=r"^t\.cfg:5: unknown key 'bogus' in camera$"):
        Scene.parse(text, "t.cfg")


def test_trace_refuses_settings_out_of_range():
    """em_scene_set_* return nothing, so em_trace checks what they set."""
    for apply in (lambda s: s.set_resolution(0, 4), lambda s: s.set_resolution(4, 20000),
                  lambda s: s.set_samples(0), lambda s: s.set_samples(5000)):
        scene = Scene.parse(ENV, "t.cfg")
        apply(scene)
        with pytest.raises(EnvmapError, match=r"^t\.cfg: "):
            scene.trace()


# ---- files and relative paths ---------------------------------------------------

def test_relative_filenames_resolve_against_the_scene_folder(tmp_path):
    folder = tmp_path / "course"
    folder.mkdir()
    (folder / "scene.cfg").write_text('environment_light { filename = "Cubemap/x_cross.hdr"; }\n')
    scene = Scene.load(folder / "scene.cfg")
    assert scene.environment_path == folder / "Cubemap" / "x_cross.hdr"


def test_absolute_filenames_are_kept(tmp_path):
    (tmp_path / "scene.cfg").write_text('environment_light { filename = "/maps/x.hdr"; }\n')
    assert Scene.load(tmp_path / "scene.cfg").environment_path == Path("/maps/x.hdr")


def test_a_scene_named_without_a_folder_keeps_relative_names(tmp_path, monkeypatch):
    (tmp_path / "scene.cfg").write_text('environment_light { filename = "Cubemap/x.hdr"; }\n')
    monkeypatch.chdir(tmp_path)
    assert Scene.load("scene.cfg").environment_path == Path("Cubemap/x.hdr")
    assert Scene.parse(ENV, "t.cfg", "sub/dir/").environment_path == Path("sub/dir/map.hdr")


def test_load_errors_name_the_file(tmp_path):
    missing = tmp_path / "missing.cfg"
    with pytest.raises(EnvmapError, match=f"^{missing}: cannot open") as info:
        Scene.load(missing)
    assert info.value.code == EM_ERR_IO
    bad = tmp_path / "bad.cfg"
    bad.write_text(ENV + "sphere { radius = 1; radus = 2; }\n")
    with pytest.raises(EnvmapError, match=f"^{bad}:2: unknown key 'radus' in sphere$"):
        Scene.load(bad)
    huge = tmp_path / "huge.cfg"
    huge.write_bytes(b"//" + b"x" * (1 << 20))
    with pytest.raises(EnvmapError) as info:
        Scene.load(huge)
    assert info.value.code == EM_ERR_TOO_LARGE


# ---- the scene files the project ships -----------------------------------------

def shipped_scenes() -> list[Path]:
    return [PROJECT_ROOT / "envmap_test.cfg"] + sorted((PROJECT_ROOT / "scenes").glob("*.cfg"))


@pytest.mark.parametrize("path", shipped_scenes(), ids=lambda p: p.name)
def test_shipped_scenes_parse_and_name_a_map_in_cubemap(path):
    scene = Scene.load(path)
    assert scene.hdr_gamma == 1.0
    env = Path(os.path.normpath(scene.environment_path))
    assert env.parent == PROJECT_ROOT / "Cubemap"
    assert env.name.endswith(".hdr")


def test_envmap_test_cfg_is_the_handouts_scene():
    scene = Scene.load(PROJECT_ROOT / "envmap_test.cfg")
    assert (scene.width, scene.height) == (512, 512)
    assert scene.environment_path == PROJECT_ROOT / "Cubemap" / "test_environment_map.hdr"
    text = (PROJECT_ROOT / "envmap_test.cfg").read_text()
    for probe in ("beach", "building", "campus", "galileo", "grace", "kitchen", "rnl", "uffizi"):
        assert f'//  filename = "Cubemap/{probe}_cross.hdr";' in text


# ---- the key table and the documentation comment ---------------------------------
# scene.c describes each key once, in a table (name, type, range, default or
# REQUIRED, field); its top comment lists the blocks, keys and defaults for a
# reader. These tests hold the two together, and the comment to the parser.

SCENE_C = PROJECT_ROOT / "reference" / "src" / "scene.c"
BLOCK_TIMES = {"AT_MOST_ONCE": "at most once", "ANY_NUMBER": "any number", "EXACTLY_ONCE": "required"}


def numbers(text: str) -> tuple[float, ...]:
    return tuple(float(x) for x in re.findall(r"-?\d+(?:\.\d*)?", text))


def documented_keys() -> dict[str, tuple[str, dict]]:
    """{block: (times, {key: default numbers, or "required"})} from the
    listing in scene.c's top comment."""
    head = SCENE_C.read_text().split("*/", 1)[0]
    listing = head.split("must agree with", 1)[1].split("Every error", 1)[0]
    texts: dict[str, str] = {}
    block = None
    for line in listing.splitlines():
        if m := re.match(r"^ \*   (\w+) +(.*)$", line):
            block = m.group(1)
            texts[block] = m.group(2)
        elif (m := re.match(r"^ \* {10,}(.*)$", line)) and block:
            texts[block] += " " + m.group(1)
    documented = {}
    for block, text in texts.items():
        times = ("any number" if text.startswith("(any number)") else
                 "required" if text.startswith("(required)") else "at most once")
        # Remarks in parentheses have letters; tuples of defaults do not.
        text = re.sub(r"\s*\([^()]*[A-Za-z][^()]*\)", "", text)
        keys: dict = {}
        for item in filter(None, (part.strip() for part in text.split(";"))):
            if item.endswith(" required"):
                for key in re.split(r",\s*|\s+and\s+", item.removesuffix(" required")):
                    keys[key.strip()] = "required"
            else:
                key, default = item.split("=")
                keys[key.strip()] = numbers(default)
        documented[block] = (times, keys)
    return documented


def tabled_keys() -> dict[str, tuple[str, dict]]:
    """The same, from the key tables in scene.c."""
    source = SCENE_C.read_text()
    tables = dict(re.findall(r"static const key_spec (\w+)\[\] = \{(.*?)\n\};", source, re.S))
    blocks = re.search(r"static const block_spec blocks\[BLOCK_COUNT\] = \{(.*?)\n\};", source, re.S).group(1)
    tabled = {}
    for block, table, times in re.findall(r'\{"(\w+)", (\w+), KEY_COUNT\(\w+\), \w+, (\w+)\}', blocks):
        keys = {}
        for key, default in re.findall(r'\{"(\w+)",.*?(REQUIRED|DEFAULT\([^)]*\)), \w+\},', tables[table]):
            keys[key] = "required" if default == "REQUIRED" else numbers(default)
        tabled[block] = (BLOCK_TIMES[times], keys)
    # Every row was read: one field macro per key.
    assert sum(len(keys) for _, keys in tabled.values()) == len(re.findall(r"\b[A-Z0-9]+_IN\(em_", source))
    return tabled


def test_the_comment_lists_the_tables_blocks_keys_and_defaults():
    tabled = tabled_keys()
    assert list(tabled) == ["camera", "sampling", "sphere", "environment_light"]
    assert tabled["sphere"] == ("any number", {"center": "required", "radius": "required",
                                               "material": "required", "ior": (1.5,), "tint": (1.0, 1.0, 1.0)})
    assert documented_keys() == tabled


def test_the_documented_defaults_and_required_keys_are_the_parsers():
    """Written out, the comment's defaults give the scene that leaving them
    out gives; leaving out a key the comment calls required is an error."""
    fill = {"center": "(0, 0, -3)", "radius": "1", "material": '"glass"', "filename": '"map.hdr"'}
    documented = documented_keys()

    def text(block_keys: dict[str, dict[str, str]]) -> str:
        return "".join(f"{block} {{ {' '.join(f'{k} = {v};' for k, v in keys.items())} }}\n"
                       for block, keys in block_keys.items())

    required = {block: {k: fill[k] for k, d in keys.items() if d == "required"}
                for block, (_, keys) in documented.items()}
    written = {block: {**required[block], **{k: "(" + ", ".join(f"{x:g}" for x in d) + ")"
                                             for k, d in keys.items() if d != "required"}}
               for block, (_, keys) in documented.items()}
    explicit, implicit = Scene.parse(text(written), "t.cfg"), Scene.parse(text(required), "t.cfg")
    assert (explicit.width, explicit.height, explicit.hdr_gamma) == (implicit.width, implicit.height,
                                                                     implicit.hdr_gamma)
    assert same_scene(text(written), text(required))

    for line, (block, keys) in enumerate(required.items(), start=1):
        for key in keys:
            without = {**required, block: {k: v for k, v in keys.items() if k != key}}
            with pytest.raises(EnvmapError, match=rf"^t\.cfg:{line}: {block} has no '{key}'$"):
                Scene.parse(text(without), "t.cfg")
    for block, (times, _) in documented.items():
        if times == "required":
            with pytest.raises(EnvmapError, match=rf"^t\.cfg:\d+: no {block} block$"):
                Scene.parse(text({b: k for b, k in required.items() if b != block}), "t.cfg")
        once = text({**required, "extra": {}}).replace("extra {  }", text({block: required[block]}).strip())
        if times == "any number":
            Scene.parse(once, "t.cfg")
        else:
            with pytest.raises(EnvmapError, match=rf"second {block} block"):
                Scene.parse(once, "t.cfg")
