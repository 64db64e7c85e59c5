"""What the zoos with truth sidecars share (tests/submissions/offmodel/,
patterns/): each X.cpp's truth in X.json, written before grading; the
verdict of a report against it; and the same submission over the handout's
readTexture, the control that fetchColor's points are compared with."""
from __future__ import annotations

import json
import re
from pathlib import Path

# The handout's readTexture, written independently of every zoo file.
HANDOUT_READ = """Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int x0 = std::clamp((int)px, 0, m_FaceWidth - 1), y0 = std::clamp((int)py, 0, m_FaceHeight - 1);
    const int x1 = std::min(x0 + 1, m_FaceWidth - 1), y1 = std::min(y0 + 1, m_FaceHeight - 1);
    const double a = px - (int)px, b = py - (int)py;
    auto at = [&](int x, int y) { const float* p = addr + 3 * (y * m_FaceWidth + x); return Color(p[0], p[1], p[2]); };
    return (1 - b) * ((1 - a) * at(x0, y0) + a * at(x1, y0)) + b * ((1 - a) * at(x0, y1) + a * at(x1, y1));
}
"""
# The ids of fetchColor's mistakes (MAPPING) and of readTexture's (FILTERING) a
# zoo's truth may need or forbid (the blind zoos).
MAPPING = {"u-flipped", "v-flipped", "uv-swapped", "wrong-face", "uv-mismatch", "face-order", "uv-rotated",
           "opengl-table", "signed-major", "uv-inset", "uv-offset", "not-divided-by-m", "float-precision",
           "tie-untouched-face", "fetch-not-returned", "asks-otherwise", "address-not-face-start", "kept-between-calls",
           "coordinate-wraps", "uv-clamped-inward"}
FILTERING = {"nearest-neighbor", "half-texel-offset", "weights-swapped", "wrapped-edge", "unclamped-edge",
             "constant-weights", "not-a-blend", "rows-flipped", "columns-flipped", "texture-v-flipped",
             "texture-u-flipped", "texture-uv-swapped", "scaled-by-size-minus-one", "scaled-by-size-plus-one",
             "texel-offset", "truncation-of-negatives", "texel-index-transposed", "width-height-swapped",
             "lattice-rounded", "fractions-exchanged", "edge-single-texel"}
READ_BLOCK = re.compile(r"// readTexture:begin\n.*?// readTexture:end\n", re.S)


class Zoo:
    def __init__(self, folder: Path):
        self.folder = folder
        self.names = sorted(p.stem for p in folder.glob("*.cpp"))

    def truth(self, name: str) -> dict:
        return json.loads((self.folder / f"{name}.json").read_text())

    def verdict(self, name: str, found: set) -> tuple[set, set]:
        """(missing, false) diagnoses of `found` against the sidecar's truth."""
        t = self.truth(name)
        causes = {(i, f) for i, f in t["causes"]}
        allowed = causes | {(i, f) for i, f in t["per_face"]}
        return causes - found, {d for d in found - allowed if d[0] not in t["symptoms"]}

    def with_handout_read(self, name: str) -> str | None:
        """The submission's source with its readTexture replaced by the
        handout's; None when its readTexture already is the handout's."""
        src = (self.folder / f"{name}.cpp").read_text()
        block = READ_BLOCK.search(src)
        assert block, f"{name}: no readTexture block"
        if block.group(0).split("\n", 1)[1].rsplit("// readTexture:end", 1)[0] == HANDOUT_READ:
            return None
        return READ_BLOCK.sub("// readTexture:begin\n" + HANDOUT_READ.replace("\\", "\\\\") + "// readTexture:end\n", src)
