"""The catalogue of diagnosis ids: what each one means, in plain words.

Checks attach a grader.grading.results.Diagnosis (id, face, detail) to what they
find; reports look the id up here for the title, the explanation and what to
do about it. The words are written for a student who has the handout; the
conventions they cite are docs/assignment.md's. docs/diagnoses.md is generated
from this table (`python -m grader.grading.catalogue > docs/diagnoses.md`), and a test
checks that the two agree. Each entry names the modules that emit it;
tests/unit/grading/test_diagnosis_catalogue.py holds each id to them (and
each of them to the ids it emits).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..i18n import N_, Translated, _

# Kinds, in the order reports list them: what stops grading first, then the
# mapping (fetchColor), the filtering (readTexture), and what renders show.
KINDS = Translated({
    "build": N_("Building"),
    "runtime": N_("Running"),
    "mapping": N_("fetchColor: from a direction to a face and (u, v)"),
    "filtering": N_("readTexture: from (u, v) to a colour"),
    "render": N_("What the renders show"),
    "speed": N_("Speed"),
})


@dataclass(frozen=True)
class DiagnosisInfo:
    """The words are kept in English (the catalogue's ids, grader/i18n/__init__.py)
    and read out in the current language."""
    id: str
    kind: str             # a KINDS key
    emitted_by: tuple[str, ...]   # the modules (under grader.) that emit it: a Diagnosis, a refusal,
                                  # a SubmissionError with this id, or their DIAGNOSIS_IDS holds it
    title_id: str         # one line, plain words
    explanation_id: str   # what happened and why it matters
    what_to_do_id: str    # the fix, or how to find it

    @property
    def title(self) -> str:
        return _(self.title_id)

    @property
    def explanation(self) -> str:
        return _(self.explanation_id)

    @property
    def what_to_do(self) -> str:
        return _(self.what_to_do_id)


_ENTRIES = [
    # ---- building ---------------------------------------------------------
    DiagnosisInfo(
        "build-error", "build", ("build",),
        N_("Your code did not compile"),
        N_("The compiler stopped with errors, so none of the checks could run. The "
        "compiler's messages are shown below the score."),
        N_("Fix the first error in the log first: later errors are often caused by "
        "it. Build with the student template (`make`, or `make selfcheck` to run "
        "the visible checks too) before you submit."),
    ),
    DiagnosisInfo(
        "no-source", "build", ("build", "intake"),
        N_("No EnvironmentMap.cpp in your submission"),
        N_("The grader grades one file, EnvironmentMap.cpp, and could not find it "
        "in what you submitted. The message lists what your submission holds."),
        N_("Submit EnvironmentMap.cpp itself, or a folder, .zip, .tar or .tar.gz "
        "that holds it (under that name)."),
    ),
    DiagnosisInfo(
        "empty-submission", "build", ("build", "intake"),
        N_("Your submission is empty"),
        N_("The file, folder or archive you submitted holds nothing to grade (or "
        "EnvironmentMap.cpp in it is empty)."),
        N_("Check that you uploaded the right file, and that it was saved before "
        "you uploaded it."),
    ),
    DiagnosisInfo(
        "unknown-format", "build", ("build", "intake"),
        N_("The grader cannot read what you submitted"),
        N_("What you submitted is neither a C++ source file nor an archive the "
        "grader reads (.zip, .tar, .tar.gz), for example a .rar or .7z "
        "archive, a compiled program, or a source saved as UTF-16. The grader "
        "tells formats apart by their contents, not their names."),
        N_("Submit EnvironmentMap.cpp saved as plain (UTF-8) text, or a .zip, "
        ".tar or .tar.gz made with your system's ordinary tools."),
    ),
    DiagnosisInfo(
        "unreadable-archive", "build", ("build", "intake"),
        N_("Your archive could not be read"),
        N_("The archive is damaged, incomplete, password-protected, uses a "
        "compression method the grader does not read (such as Deflate64), or "
        "is far larger than a submission needs once unpacked."),
        N_("Make the archive again with your system's ordinary zip or tar, without "
        "a password, check that it opens, and submit it again. Submitting "
        "EnvironmentMap.cpp alone always works."),
    ),
    DiagnosisInfo(
        "refused-include", "build", ("build",),
        N_("Your code includes a file it may not"),
        N_("A submission may include only the C++ standard library and the "
        "template's headers (EnvironmentMap.h, Vector3.h, Color.h), by name. "
        "Including by path (from /, with '..', from /dev or /proc), through a "
        "macro, or reading files with #embed, .incbin or file pragmas is "
        "refused before anything is compiled. The message names the line."),
        N_("Include headers plainly, as in #include <cmath> or #include "
        "\"EnvironmentMap.h\", and put everything else you need in "
        "EnvironmentMap.cpp itself."),
    ),
    DiagnosisInfo(
        "calls-reference", "build", ("build",),
        N_("Your code calls the grader's reference solution"),
        N_("Your code calls functions of the grader's reference solution (their names start with em_). "
        "They are not part of your program: the grader builds your file with "
        "the template's headers and its own loader only, so the answer cannot "
        "come from there. The message names the functions."),
        N_("Compute fetchColor and readTexture with your own code; remove the "
        "declarations and calls of em_* functions."),
    ),
    DiagnosisInfo(
        "forbidden-object", "build", ("build",),
        N_("Your compiled code holds something a submission may not"),
        N_("The object file compiled from your code uses a function that is "
        "neither in the C/C++ standard library nor in EnvironmentMap.h, or "
        "holds sections or assembler directives an ordinary C++ file does not "
        "make (link-time-optimisation data, file-reading .incbin, assembler "
        "macros). The message says which."),
        N_("Write plain C++ using the standard library. Define every helper in "
        "your own file, and remove inline assembly and section attributes."),
    ),
    DiagnosisInfo(
        "load-error", "build", ("checks.context",),
        N_("Your compiled code could not be loaded"),
        N_("The code compiled, but the library built from it could not be "
        "loaded, for example because a function it declares is never defined, "
        "or because code that runs when it loads (a global object's "
        "constructor) failed. This is more often a build problem than a "
        "mistake in your lookup."),
        N_("Build and run the student template locally (`make selfcheck`). Define "
        "every function you declare, and do no work in global variables' "
        "initialisers. If it works locally, tell your instructor."),
    ),
    # ---- running ----------------------------------------------------------
    DiagnosisInfo(
        "crash", "runtime", ("checks.context",),
        N_("Your code crashed"),
        N_("The program stopped with a signal (for example SIGSEGV, a segmentation "
        "fault) while running your code. The grader repeated the failing batch "
        "to find the first input that crashes; it is named in the details."),
        N_("Call your function with exactly that input from a small test and run "
        "it under a debugger. Usual causes: a texel index outside the face "
        "(x = -1 or x = W, as the handout warns), a face pointer that was never "
        "set because no branch of the face choice was taken (every comparison "
        "with NaN is false), dividing an integer by zero, or a function that "
        "calls itself without end (a stack overflow)."),
    ),
    DiagnosisInfo(
        "out-of-bounds-read", "runtime", ("checks.context",),
        N_("readTexture read outside the face"),
        N_("Your code read memory just before or just after the texels it was "
        "given. The grader puts an inaccessible page right next to the "
        "texture, so such a read is caught every time, even where a normal "
        "program would silently read a neighbouring face or garbage. The "
        "handout warns about exactly this: reading x = -1 or x = W."),
        N_("Clamp both lattice points to the face: x0 and x1 = x0 + 1 to "
        "`[0, W-1]`, y0 and y1 = y0 + 1 to `[0, H-1]`. Remember that u = 1 "
        "gives `u*W = W`, and that x1 goes past the edge whenever x0 = W-1."),
    ),
    DiagnosisInfo(
        "exception", "runtime", ("checks.context",),
        N_("Your code threw a C++ exception that nobody caught"),
        N_("An exception (for example std::out_of_range from vector::at, or "
        "std::bad_alloc when memory runs out) left fetchColor or readTexture, "
        "which ends the program."),
        N_("Find which call throws for the input named in the details. A lookup "
        "needs no allocation and no checked container access: index the "
        "texel buffer directly, with clamped indices. For std::bad_alloc, look "
        "for memory allocated on every call or in a loop."),
    ),
    DiagnosisInfo(
        "timeout", "runtime", ("checks.context",),
        N_("Your code took too long and was stopped"),
        N_("A check did not finish within its time limit. Only that check lost its "
        "points; the other checks still ran."),
        N_("Look for a loop that may never end, for example one that searches for "
        "the face or walks along the ray, and what it does for a zero, NaN or "
        "infinite direction. A lookup is a few comparisons, one division and "
        "four texel reads: it needs no loop."),
    ),
    DiagnosisInfo(
        "exited", "runtime", ("checks.context",),
        N_("Your code ended the program"),
        N_("The program stopped in the middle of a check without crashing, for "
        "example through exit() or quick_exit(). The checks that were running "
        "could not finish."),
        N_("Remove calls that end the program from fetchColor and readTexture. "
        "For an input you cannot handle, return a colour (black, for instance) "
        "instead."),
    ),
    DiagnosisInfo(
        "forbidden-syscall", "runtime", ("checks.context",),
        N_("Your code tried something the grader does not allow"),
        N_("Your code tried to start a process, open a file or a network "
        "connection, or another operation that is blocked while grading. A "
        "lookup only needs arithmetic and reads from the texture it is given."),
        N_("Remove debugging code that writes files, calls system() or starts "
        "programs. Print to the terminal while you debug locally, and take it "
        "out before submitting."),
    ),
    DiagnosisInfo(
        "protocol", "runtime", ("checks.context",),
        N_("Your code disturbed the grader's connection to it"),
        N_("The grader talks to your code through a pipe, and the replies it got "
        "were garbled: your code wrote to a file descriptor it does not own, or "
        "wrote over memory that is not its own (past the end of an array, "
        "through an uninitialised pointer)."),
        N_("Write only into the colour you return. Check every array index and "
        "pointer in fetchColor and readTexture, and remove code that writes to "
        "files or descriptors."),
    ),
    DiagnosisInfo(
        "nan-output", "runtime", ("checks.fetch_sweep", "checks.stability"),
        N_("Your code returned NaN or infinity"),
        N_("For some finite, non-zero direction your code returned a colour that "
        "is not a number (NaN) or is infinite. One such pixel spoils a whole "
        "render. When the grader found the cause, it is named beside this "
        "(`float-precision`: components converted to float; `length-overflow`: "
        "a squared length; `not-divided-by-m`: a division by the length instead of m)."),
        N_("Fix the cause named beside this one first. Otherwise: divide only by "
        "m, the absolute value of the largest component, which "
        "is never zero for a non-zero direction; dividing by another "
        "component divides by zero on the axes. Do not square the direction "
        "in float (1e30 squared overflows, 1e-30 squared becomes 0): the "
        "pyramid projection needs no length. Check that every variable is set "
        "on every path."),
    ),
    # ---- mapping (fetchColor) --------------------------------------------
    # Patterns first: one cause over several faces reads before the per-face
    # symptoms it explains (reports list mistakes in this order).
    DiagnosisInfo(
        "signed-major", "mapping", ("checks.instruments.face_map",),
        N_("You divide by the signed major component"),
        N_("On -X, -Y and -Z, and only there, u and v both run the wrong way: "
        "those are the faces where the major component is negative, so "
        "dividing by it (instead of by its magnitude m) flips both signs."),
        N_("Divide by m = |major component| (fabs) and keep the signs of the "
        "(u, v) table in README.md; do not flip the table's signs to make up "
        "for it."),
    ),
    DiagnosisInfo(
        "opengl-table", "mapping", ("checks.instruments.face_map",),
        N_("You use OpenGL's cube-map table, not this assignment's"),
        N_("+X, -X and -Z are turned 180 degrees (u and v both run the wrong "
        "way) while +Y, -Y and +Z are right: that is exactly OpenGL's table "
        "of sc and tc per face, whose conventions differ from this "
        "assignment's."),
        N_("Take u and v for every face from the (u, v) table in README.md."),
    ),
    DiagnosisInfo(
        "face-order", "mapping", ("checks.instruments.face_map",),
        N_("Your face numbers are in another order than the buffer's"),
        N_("Several faces read another face, one for one: your code "
        "numbers the faces in another order (for example +X, +Y, +Z, -X, -Y, -Z) "
        "than faceAddress, which takes +X, -X, +Y, -Y, +Z, -Z. The details "
        "give your order."),
        N_("Pass faceAddress the handout's numbers (FACE_POS_X .. FACE_NEG_Z), or "
        "convert yours in one place. Keep your (u, v) formulas."),
    ),
    DiagnosisInfo(
        "uv-rotated", "mapping", ("checks.instruments.face_map",),
        N_("On several faces, (u, v) are turned 90, 180 or 270 degrees"),
        N_("On the faces named, the picture is turned about the face's centre: u "
        "and v are swapped and one of them runs the wrong way (90 or 270 "
        "degrees), or both run the wrong way (180 degrees). One turn on several "
        "faces has one cause, for example faces taken from a turned picture of "
        "the cross."),
        N_("Take u and v for each face from the (u, v) table in README.md, both "
        "the component and its sign. The details say what your u and v are."),
    ),
    DiagnosisInfo(
        "wrong-face", "mapping", ("checks.instruments.face_map",),
        N_("fetchColor read from the wrong face"),
        N_("For directions that exit through one face, your code read the colour "
        "from another face (the details say which). The face is the one along "
        "the axis with the largest absolute component, + or - by its sign; "
        "faces are stored in the order +X, -X, +Y, -Y, +Z, -Z, face k "
        "starting `k*W*H*3` floats into the buffer."),
        N_("Compare absolute values (fabs) when choosing the axis, then use the "
        "sign to choose between + and -. Check the face index you pass to "
        "readTexture against the order above, and the offset (the factor 3 "
        "for RGB is easy to forget). Rendering the test map is a quick check: "
        "the red, green and blue arrows must point along +x, +y and +z."),
    ),
    DiagnosisInfo(
        "u-flipped", "mapping", ("checks.instruments.face_map",),
        N_("On this face, u runs the wrong way"),
        N_("The face's picture is mirrored left to right: where the correct u is "
        "0.2 your code uses 0.8. On the face named, u should be the value in "
        "the (u, v) table (README.md, 'Conventions') (for example `(1 + z/m)/2` on +X but "
        "`(1 - z/m)/2` on -X)."),
        N_("Check the sign in front of the component that gives u on this face. "
        "Each face has its own sign: they are chosen so that neighbouring "
        "faces of the cross meet without a jump."),
    ),
    DiagnosisInfo(
        "v-flipped", "mapping", ("checks.instruments.face_map",),
        N_("On this face, v runs the wrong way"),
        N_("The face's picture is upside down: where the correct v is 0.2 your "
        "code uses 0.8. v = 0 is the bottom row of the face (y = 0 in the "
        "buffer), not the top. On the face named, v should be the value in "
        "the (u, v) table (README.md, 'Conventions') (for example `(1 - z/m)/2` on -Y, and "
        "`(1 - y/m)/2` on +Z, the back face that sits upside down in the cross)."),
        N_("Check the sign in front of the component that gives v on this face."),
    ),
    DiagnosisInfo(
        "uv-inset", "mapping", ("checks.instruments.face_map",),
        N_("fetchColor moves (u, v) inward from the face's border"),
        N_("Read back from your answers, (u, v) run from a little above 0 to a "
        "little below 1 on the faces: the face's outer texels are never "
        "reached and the picture is slightly magnified. The handout's (u, v) "
        "run from exactly 0 to 1; readTexture's clamp already keeps the "
        "blend inside the face."),
        N_("Pass fetchColor's (u, v) to readTexture as the table gives them, "
        "without scaling or insetting them."),
    ),
    DiagnosisInfo(
        "uv-offset", "mapping", ("checks.instruments.face_map",),
        N_("fetchColor shifts (u, v) by a constant"),
        N_("Read back from your answers, fetchColor reads a fixed distance away "
        "from the (u, v) the table gives, on every face."),
        N_("Pass (1 + s/m)/2 and (1 + t/m)/2 to readTexture as they are: no "
        "half-texel correction is needed, readTexture's p = (uW, vH) already "
        "says where the texels are."),
    ),
    DiagnosisInfo(
        "uv-swapped", "mapping", ("checks.instruments.face_map",),
        N_("On this face, u and v are swapped"),
        N_("Your fetchColor used the component that should give v for u and the "
        "other way round on this face, so the face appears turned on its "
        "diagonal. (A readTexture that swaps them swaps them on every face: "
        "that is `texture-uv-swapped`.)"),
        N_("Take u and v from the components the (u, v) table (README.md, 'Conventions') names "
        "for this face."),
    ),
    DiagnosisInfo(
        "not-divided-by-m", "mapping", ("checks.instruments.face_map",),
        N_("fetchColor does not divide by m, the largest |component|"),
        N_("The point where the ray meets the face is found by dividing the "
        "direction by m, the absolute value of its largest component (the "
        "handout's pyramid with the cube centre at its apex). Your (u, v) "
        "change with the direction's length, or follow another curve: the "
        "components were used as they are, divided by the direction's length "
        "instead of m, or turned into angles. Normalising the direction does "
        "not replace this division."),
        N_("Compute `m = |largest component|` and use `(1 + a/m)/2` with the signs "
        "from the table. Directions are not unit length: do not normalise them, "
        "dividing by m is all the scaling needed (normalising squares the "
        "components, which overflows for huge directions: `length-overflow`)."),
    ),
    DiagnosisInfo(
        "not-implemented", "mapping", ("checks.instruments.face_map",),
        N_("fetchColor still returns black"),
        N_("Every direction gave black (or a colour that is not in the texture), "
        "as the starting code does: fetchColor does not look anything up yet."),
        N_("Write fetchColor as the handout's section 4 says: choose the face, "
        "compute (u, v) from the (u, v) table in README.md and return "
        "`readTexture(faceAddress(face), u, v)`."),
    ),
    DiagnosisInfo(
        "uv-mismatch", "mapping", ("checks.instruments.face_map",),
        N_("On this face, (u, v) follow no pattern the grader recognises"),
        N_("Your code reads the right face, but at places that are neither the "
        "correct (u, v) nor a flip or swap of them. The per-face table in the "
        "check's output shows how much of the face the closest guess explains."),
        N_("Print u and v for a few directions toward this face (for example the "
        "face's centre, which must give (0.5, 0.5), and its corners, which "
        "must give 0 or 1) and compare them with the (u, v) table in README.md."),
    ),
    DiagnosisInfo(
        "uv-range", "mapping", ("checks.instruments.face_map",),
        N_("(u, v) are not mapped to [0, 1]"),
        N_("Your code reads the right face and the right direction of u and v, "
        "but does not turn the face-plane coordinate s = component / m (which "
        "runs from -1 to 1) into u = (1 + s) / 2: it uses s itself, 1 + s or "
        "s / 2, so half the face is never read and the rest is stretched."),
        N_("Use u = (1 + s) / 2 and v = (1 + t) / 2 with the signs of the (u, v) "
        "table in README.md; the face's centre must give (0.5, 0.5)."),
    ),
    DiagnosisInfo(
        "tie-untouched-face", "mapping", ("checks.instruments.face_map",),
        N_("A direction on an edge or corner samples a face it does not touch"),
        N_("When two or three components tie as the largest in magnitude, the "
        "direction lies on an edge or corner of the cube and every face it "
        "touches is a correct answer. Your face choice sends such directions "
        "to a face they do not touch, usually because every test uses a "
        "strict > : a tie fails them all and falls through to the last branch."),
        N_("Compare with >= (for example `ax >= ay && ax >= az`), so that a tie "
        "picks one of the tied axes. The details name a direction to try."),
    ),
    DiagnosisInfo(
        "black-without-lookup", "mapping", ("checks.fetch_sweep",),
        N_("fetchColor returns black without calling readTexture"),
        N_("For some directions your fetchColor returned black and made no "
        "readTexture call at all, while it looks up the others. Every "
        "finite, non-zero direction exits through a face at a (u, v) in "
        "[0, 1] x [0, 1], borders included, so every one has a colour to "
        "read. The details say what the skipped directions have in common "
        "where the record shows it (a border of the face, a short length)."),
        N_("Find the condition that returns black before readTexture is "
        "called and remove it: only a zero, NaN or infinite direction may "
        "skip the lookup. Clamping the edge texels is readTexture's job, and "
        "a short direction has a face like any other."),
    ),
    DiagnosisInfo(
        "float-precision", "mapping", ("checks.instruments.face_map",),
        N_("Tiny or huge directions lose their precision in float"),
        N_("The components go through float somewhere (`float x = direction.x`, "
        "or a helper with float parameters). float cannot hold magnitudes "
        "below about 1e-38 exactly (they lose digits, then become 0, giving "
        "0/0) or above 3.4e38 at all (they become infinite), so such "
        "directions give another colour than the same direction at length 1."),
        N_("Keep the components in double until you have divided them by m, "
        "the largest magnitude: the ratios are then between -1 and 1 and "
        "safe in float."),
    ),
    DiagnosisInfo(
        "length-overflow", "mapping", ("checks.instruments.face_map",),
        N_("Huge or tiny directions overflow when squared"),
        N_("Your code squares the components (to normalise the direction, or to "
        "compare lengths): x*x + y*y + z*z overflows to infinity above "
        "|d| = 1.3e154 and underflows to 0 below about 1e-162, and dividing "
        "by infinity or 0 gives black or NaN. The cube map needs no length: "
        "only the ratios to the largest component matter."),
        N_("Divide by m, the largest |component|, instead of the length; if you "
        "must normalise, divide by m first and square afterwards."),
    ),
    DiagnosisInfo(
        "length-dependent", "mapping", ("checks.stability",),
        N_("The same direction gives another answer at another length"),
        N_("The grader asked the same direction at several lengths, scaled by "
        "powers of two (which change no digit of the ratios between its "
        "components), and your fetchColor asked readTexture for another face "
        "or (u, v), or for nothing, at some of them. Only the ratios to m "
        "matter, so the length must change nothing. The two calls shown are "
        "what was observed; what in your code depends on the size of the "
        "components is for you to find: a guard that treats short directions "
        "as zero, a product computed before the division (0.5 * z is 0 for "
        "the tiniest z), integer magnitudes when choosing the axis (an int "
        "abs, an (int) cast), float variables, or a squared length."),
        N_("Run your fetchColor on the two calls shown and print each value "
        "they compute until the first one that differs in more than its "
        "scale. Choose the axis with fabs in double, divide by m before "
        "anything else, and treat only a zero, NaN or infinite direction as "
        "having no face."),
    ),
    DiagnosisInfo(
        "face-not-analysed", "mapping", ("checks.instruments.face_map",),
        N_("The analysis of one face stopped at a crash"),
        N_("The grader could not find out what fetchColor does toward this face, "
        "because your code crashed on the directions it needed. The face is "
        "listed so that it is not mistaken for a correct one; the details "
        "name the input that crashed."),
        N_("Fix the crash first (see the crash diagnosis); the next submission's "
        "report will then say what happens on this face."),
    ),
    DiagnosisInfo(
        "coordinate-wraps", "mapping", ("checks.fetch_sweep",),
        N_("fetchColor turns a coordinate of 1 into 0 at a face's edge"),
        N_("Where the table gives u or v exactly 1 (a direction on the edge between "
        "two faces), your fetchColor asks readTexture for 0 (or for 1 where it "
        "gives 0): the opposite side of the same face. Code does this with u - "
        "floor(u), fmod(u, 1.0) or a repeating wrap, which are right for a "
        "repeating texture and wrong for a cube face, whose edge at u = 1 belongs "
        "to it."),
        N_("Keep u and v as the table computes them, in [0, 1] with 1 included; if "
        "you guard them at all, clamp them to [0, 1]."),
    ),
    DiagnosisInfo(
        "uv-clamped-inward", "mapping", ("checks.fetch_sweep",),
        N_("fetchColor keeps u and v away from the face's border"),
        N_("Your fetchColor never asks readTexture for a u or v below some small "
        "margin or above 1 minus it (for example a clamp to [0.001, 0.999]): "
        "directions nearer a face's border than that ask for a place moved "
        "inward. readTexture already clamps its lattice points, so (u, v) at 0 "
        "and 1 are safe to pass."),
        N_("Pass the table's (u, v) unchanged; if you clamp at all, clamp to [0, 1]."),
    ),
    DiagnosisInfo(
        "discontinuous-seam", "mapping", ("checks.stability",),
        N_("Colours jump where two faces meet"),
        N_("Moving a direction across the edge between two faces changes the "
        "colour by much more than the handout's method does there. The "
        "handout's bilinear lookup clamps inside each face, so a small step "
        "there (the difference between two neighbouring texels) is expected "
        "and costs nothing; this is larger. Usually one of the two faces has u or v running the "
        "wrong way, or (u, v) go wrong near the edge of the face."),
        N_("Use the (u, v) table in README.md ('Conventions'): its signs make neighbouring faces of "
        "the cross continuous. The details name the edge; compare the two "
        "faces' formulas along it."),
    ),
    DiagnosisInfo(
        "fetch-depends-on-earlier-faces", "mapping", ("checks.instruments.process_state",),
        N_("fetchColor answers otherwise after faces of another size"),
        N_("The grader asked your fetchColor the same directions on the same faces "
        "twice: in a program whose first faces they were, and in one that had "
        "looked up on faces of another size before. Some answers differ (the "
        "details give one direction and both colours), so something depends on "
        "what happened earlier: a static variable, a cache, a size or a table "
        "kept from an earlier call. The sweep's set on faces of a second size and "
        "the checks that look at whole maps (arrows, stability, renders) were "
        "judged both ways; the lower score counts."),
        N_("Compute everything from the direction, `m_FaceWidth`, `m_FaceHeight` "
        "and the texels on every call: no `static` variables, no caches."),
    ),
    # ---- filtering (readTexture) -----------------------------------------
    DiagnosisInfo(
        "kept-between-calls", "filtering", ("checks.read_texture",),
        N_("readTexture keeps something from an earlier call"),
        N_("On the same face size and texels, your readTexture read other texels "
        "after it had been called on a face of another size than it does when it "
        "is called first. Something computed once is reused: a face size kept in "
        "a static variable, a cache, a lookup table built on the first call."),
        N_("Compute everything readTexture needs from its arguments and "
        "`m_FaceWidth`, `m_FaceHeight` on every call: no `static` variables, no "
        "caches."),
    ),
    DiagnosisInfo(
        "face-size-dependent", "filtering", ("checks.read_texture",),
        N_("readTexture answers otherwise on large faces"),
        N_("On every small face the grader measured, your readTexture answered as "
        "the handout's equations do; on a large face of random texels it did not. "
        "The code takes another path for some face sizes (a test on m_FaceWidth "
        "or m_FaceHeight, a size limit, an array of fixed size)."),
        N_("Use one computation for every face size: p = (u*W, v*H), the four "
        "lattice points clamped to the face, equations (1)-(3)."),
    ),
    DiagnosisInfo(
        "not-a-blend", "filtering", ("checks.read_texture",),
        N_("readTexture's answer is not a blend of the texels it reads"),
        N_("The grader measured which texels your readTexture reads, and with what "
        "weights, on textures that are 1 on one texel and 0 elsewhere. On a random "
        "texture its answer was not those weights applied to the texels: the "
        "answer depends on the texels' values in another way (a test on the "
        "colour, a maximum, a channel mixed with another), on the face, or on "
        "earlier calls."),
        N_("Return `(1-beta) c0 + beta c1` with `c0`, `c1` from equations (1) and "
        "(2): weights that depend on u and v only, the same for R, G and B, and no "
        "test on the texels' values."),
    ),
    DiagnosisInfo(
        "texel-index-transposed", "filtering", ("checks.read_texture",),
        N_("readTexture's texel index is transposed"),
        N_("Your readTexture reads the texel the handout reads at (x, y) from "
        "`addr[3 * (x * W + y)]`: on a square face that is texel (y, x), on other "
        "faces a texel of another row, or memory past the face."),
        N_("Index the texel at `addr[3 * (y * m_FaceWidth + x)]`: y selects the "
        "row (y = 0 the bottom row), x the column."),
    ),
    DiagnosisInfo(
        "nearest-neighbor", "filtering", ("checks.read_texture",),
        N_("readTexture still returns the nearest texel"),
        N_("readTexture returns a single texel, as the starting code does, so "
        "renders show blocks. The assignment asks for bilinear interpolation "
        "of the four texels around `p = (u*W, v*H)`."),
        N_("Implement the handout's equations (1)-(3): take the lattice points "
        "around p, alpha and beta the fractional parts of p's x and y, "
        "`c0 = (1-alpha) c00 + alpha c10`, `c1 = (1-alpha) c01 + alpha c11`, "
        "`c = (1-beta) c0 + beta c1`."),
    ),
    DiagnosisInfo(
        "half-texel-offset", "filtering", ("checks.read_texture",),
        N_("readTexture is shifted by half a texel"),
        N_("Your interpolation is centred half a texel away from the handout's: "
        "for example `p = (u*W - 0.5, v*H - 0.5)`, the texel-centre convention "
        "of OpenGL. The handout defines the pixel position as `p = (u*W, v*H)`, "
        "with the lattice points at whole numbers around it, and the grader "
        "follows the handout."),
        N_("Use `p = (u*W, v*H)` without adding or subtracting 0.5; "
        "`x0 = floor(p.x)`, `alpha = p.x - x0` (and the same for y), then clamp."),
    ),
    DiagnosisInfo(
        "width-height-swapped", "filtering", ("checks.read_texture",),
        N_("readTexture mixes up the face's width and height"),
        N_("On faces that are not square, your readTexture scales u by the face "
        "height or v by the width (or indexes rows with the height), so it "
        "reads the wrong texels. Real maps have square faces, so this only "
        "shows on the grader's non-square test faces, but it is a real bug."),
        N_("Use `p = (u * m_FaceWidth, v * m_FaceHeight)`, clamp x to "
        "`[0, m_FaceWidth-1]` and y to `[0, m_FaceHeight-1]`, and index "
        "`addr[3*(y*m_FaceWidth + x)]`."),
    ),
    DiagnosisInfo(
        "scaled-by-size-minus-one", "filtering", ("checks.read_texture",),
        N_("readTexture scales u by W-1 instead of W"),
        N_("Your readTexture puts the sample at p = (u(W-1), v(H-1)), so u = 1 lands "
        "exactly on the last texel. That is a common convention elsewhere, but "
        "the handout's is p = (uW, vH): at u = 1 the clamp keeps the lattice "
        "inside the face, and every other u samples a little further right than "
        "yours."),
        N_("Use `p = (u * m_FaceWidth, v * m_FaceHeight)` as the handout's section "
        "4 says, and keep the two clamp lines for x and y."),
    ),
    DiagnosisInfo(
        "weights-swapped", "filtering", ("checks.read_texture",),
        N_("readTexture mixes the four texels with the wrong weights"),
        N_("The interpolation weights are the wrong way round: for example "
        "`alpha c00 + (1-alpha) c10` instead of `(1-alpha) c00 + alpha c10`. "
        "The nearer texel must get the larger weight."),
        N_("Follow equations (1)-(3) exactly: alpha is the fractional part of "
        "`u*W` and weighs c10 and c11 (the texels to the right); beta is the "
        "fractional part of `v*H` and weighs c1 (the row above)."),
    ),
    DiagnosisInfo(
        "fractions-exchanged", "filtering", ("checks.read_texture",),
        N_("readTexture uses beta where alpha belongs, or alpha where beta belongs"),
        N_("Your blend weighs the texels along one axis by the other axis's fraction: "
        "the fraction of vH where the handout uses the fraction of uW, or the other "
        "way round (the detail above says which axis). With both exchanged, the "
        "texel to the right of (x0, y0) gets the weight the texel above should get: "
        "code does this with c01 and c10 exchanged in equation (1), or with alpha and "
        "beta exchanged. Where the two fractions are equal the colour is right, "
        "which hides it on a diagonal."),
        N_("Follow equations (1)-(3): c0 = (1-alpha) c00 + alpha c10 blends along x "
        "(c10 is the texel to the right, x0 + 1), c1 the same one row up, and beta "
        "blends c0 and c1."),
    ),
    DiagnosisInfo(
        "lattice-rounded", "filtering", ("checks.read_texture",),
        N_("readTexture rounds p to its lattice point instead of flooring it"),
        N_("Your lattice point is round(p) (or (int)(p + 0.5)), not floor(p). Where "
        "the fraction of p is below 0.5 the blend is the handout's; where it is 0.5 "
        "or more your lattice point is one texel too far, alpha = p - x0 is "
        "negative, and the lookup extrapolates from that texel and the next one "
        "(weights above 1 and below 0) instead of blending the two texels around p."),
        N_("Take x0 = floor(p.x) and y0 = floor(p.y) (or (int) of them: p is never "
        "negative), alpha = p.x - x0 and beta = p.y - y0, so both lie in [0, 1)."),
    ),
    DiagnosisInfo(
        "edge-single-texel", "filtering", ("checks.read_texture",),
        N_("readTexture stops blending on the face's last row or column"),
        N_("On the last column (x0 = W - 1), the last row (y0 = H - 1) or both (the "
        "detail above says which) your readTexture returns the single texel (x0, y0). "
        "The handout clamps its lattice points there instead: on the last column "
        "x1 = x0 = W - 1, so the blend across x mixes one texel with itself, but the "
        "blend across y still mixes two rows by beta (and the same on the last row "
        "with alpha). Yours turns a smooth gradient into steps along that border of "
        "every face."),
        N_("Do not return early at the border: clamp x1 = min(x0 + 1, W - 1) and "
        "y1 = min(y0 + 1, H - 1), and blend the four (clamped) texels as everywhere "
        "else."),
    ),
    DiagnosisInfo(
        "texel-offset", "filtering", ("checks.read_texture",),
        N_("readTexture reads a whole texel off"),
        N_("The lattice position is shifted by a whole texel, for example "
        "p = (uW - 1, vH - 1): every colour comes from one texel to the left "
        "and below (or right and above) of where the handout reads, and the "
        "picture is shifted by one texel on every face."),
        N_("Use p = (uW, vH) with no offset; texel (x, y) sits on the lattice "
        "point (x, y)."),
    ),
    DiagnosisInfo(
        "truncation-of-negatives", "filtering", ("checks.read_texture",),
        N_("(int) truncates negative positions toward zero"),
        N_("Your p can be negative (it is shifted before rounding), and (int)p "
        "rounds toward zero, so for p between -1 and 0 it gives 0 instead of "
        "-1. The weight alpha = p - x0 then goes negative and the lookup "
        "extrapolates beyond the edge texel."),
        N_("Use floor(p) to find the lattice point below p, or (better) do not "
        "shift p: with p = (uW, vH) it is never negative."),
    ),
    DiagnosisInfo(
        "unclamped-edge", "filtering", ("checks.read_texture",),
        N_("readTexture's lattice points are not clamped to the face"),
        N_("At the edges of a face your lookup uses x = W, x = -1, y = H or "
        "y = -1: it reads the first texel of the next row, the texel before "
        "the face, or memory past the face (which crashes). This is what the "
        "handout warns about."),
        N_("Clamp x0 and x1 to [0, W-1] and y0 and y1 to [0, H-1] after "
        "computing them (u = 1 gives x0 = W, and x1 = x0 + 1 is W whenever "
        "x0 = W - 1)."),
    ),
    DiagnosisInfo(
        "wrapped-edge", "filtering", ("checks.read_texture",),
        N_("readTexture wraps around the face instead of clamping"),
        N_("At an edge your lookup reads the texel on the opposite side of the "
        "same face (x = W becomes x = 0, with % W or a repeat mode). A cube "
        "face does not repeat: its neighbour across the edge is another face."),
        N_("Clamp the lattice points to [0, W-1] and [0, H-1] instead of taking "
        "them modulo the size."),
    ),
    DiagnosisInfo(
        "scaled-by-size-plus-one", "filtering", ("checks.read_texture",),
        N_("readTexture uses p = (u(W+1), v(H+1))"),
        N_("The lattice position is scaled by W + 1 instead of W, so the lookup "
        "drifts by up to a texel toward the far edge of each face."),
        N_("Use p = (uW, vH) as in the handout."),
    ),
    DiagnosisInfo(
        "constant-weights", "filtering", ("checks.read_texture",),
        N_("readTexture's weights do not follow the position"),
        N_("Your lookup gives the texels it blends the same weights wherever p "
        "is (for example alpha = beta = 0.5, or a box filter), so the colour "
        "jumps at every texel boundary instead of changing smoothly."),
        N_("blend the four texels around p, weighted by p's fractional parts: "
        "alpha = px - x0 and beta = py - y0, computed in double (an int alpha "
        "is always 0)."),
    ),
    DiagnosisInfo(
        "rows-flipped", "filtering", ("checks.read_texture",),
        N_("readTexture reads the rows top-down"),
        N_("Your lookup reads row H-1-y (or uses 1 - v) where the handout's "
        "buffer has y = 0 as the bottom row (v = 0). Every face is upside "
        "down, whatever fetchColor does."),
        N_("Index the texel at addr[3 * (y * W + x)] with y = 0 the bottom row, "
        "as README.md describes the buffer."),
    ),
    DiagnosisInfo(
        "texture-u-flipped", "filtering", ("checks.read_texture",),
        N_("readTexture runs u from right to left"),
        N_("Your readTexture reads at 1 - u: on every face, whatever fetchColor "
        "asks for, u = 0 gives the right column instead of the left one."),
        N_("In readTexture, p's x is u times W (u = 0 is the left column, "
        "x = 0); do not flip it there."),
    ),
    DiagnosisInfo(
        "texture-v-flipped", "filtering", ("checks.read_texture",),
        N_("readTexture runs v from top to bottom"),
        N_("Your readTexture reads at 1 - v: on every face, whatever fetchColor "
        "asks for, v = 0 gives the top row instead of the bottom one."),
        N_("In readTexture, p's y is v times H (v = 0 is the bottom row, y = 0 "
        "in the buffer); do not flip it there."),
    ),
    DiagnosisInfo(
        "texture-uv-swapped", "filtering", ("checks.read_texture",),
        N_("readTexture uses u for the rows and v for the columns"),
        N_("Your readTexture takes the column from v and the row from u, on "
        "every face whatever fetchColor asks for."),
        N_("In readTexture, x comes from u (times W) and y from v (times H)."),
    ),
    DiagnosisInfo(
        "columns-flipped", "filtering", ("checks.read_texture",),
        N_("readTexture reads the columns right to left"),
        N_("Your lookup reads column W-1-x (or uses 1 - u) where the handout's "
        "buffer has x = 0 as the left column (u = 0). Every face is mirrored, "
        "whatever fetchColor does."),
        N_("Index the texel at addr[3 * (y * W + x)] with x = 0 the left column."),
    ),
    # ---- renders ----------------------------------------------------------
    DiagnosisInfo(
        "arrow-wrong", "render", ("checks.arrows",),
        N_("An axis arrow on the test map points the wrong way"),
        N_("This is the handout's own debugging check: rendered with "
        "`test_environment_map.hdr`, the red, green and blue arrows must point "
        "along +x, +y and +z. In your render the arrow named in the details "
        "points another way, so some face is chosen or oriented wrongly."),
        N_("Render `envmap_test.cfg` with the test map and compare the arrows with "
        "the axes; the annotated picture in the report shows which arrow is "
        "off. The mapping diagnoses listed with this one usually name the "
        "face to fix."),
    ),
    DiagnosisInfo(
        "arrow-missing", "render", ("checks.arrows",),
        N_("An axis arrow on the test map is missing"),
        N_("Rendered with `test_environment_map.hdr`, one of the red, green and "
        "blue arrows does not appear at all: the part of the map that holds "
        "it is never read, usually because a face is never chosen or the face "
        "offset into the buffer is wrong."),
        N_("Check that each of the six faces can be chosen and that face k is "
        "read from `k*W*H*3` floats into the buffer, in the order "
        "+X, -X, +Y, -Y, +Z, -Z."),
    ),
    DiagnosisInfo(
        "render-mismatch", "render", ("checks.renders",),
        N_("Your render differs from the reference"),
        N_("A scene rendered with your lookup was compared with the same scene "
        "rendered with the reference lookup, for its structure and for how "
        "different the two look to a person. The difference is larger than "
        "correct solutions ever show, even compiled with other settings."),
        N_("No other check names a cause (this is said only then). Look at "
        "the difference pictures in the HTML report, where bright areas are "
        "where your render is wrong, and at each check's own numbers: "
        "readTexture's worked case, the sweep's worst cases, the picture of "
        "what fetchColor asks for."),
    ),
    # ---- speed ------------------------------------------------------------
    DiagnosisInfo(
        "slow", "speed", ("checks.speed",),
        N_("Your lookups are much slower than they need to be"),
        N_("Measured in the same run, your fetchColor takes several times as long "
        "per lookup as the reference, beyond the generous band that gets full "
        "points."),
        N_("A lookup needs a few comparisons, one division per coordinate and "
        "four texel reads. Look for work that can go: allocating or copying "
        "per call, trigonometry (atan2, acos) or pow, loops over texels, "
        "printing while grading."),
    ),
    DiagnosisInfo(
        "timed-output-wrong", "speed", ("checks.speed",),
        N_("Your lookups answer differently while they are being timed"),
        N_("The speed check keeps the colours of every timed lookup and compares "
        "them with your own code's untimed answers to the same directions. They "
        "differ, so the time measured is not the time of the lookup the other "
        "checks see and does not count."),
        N_("fetchColor must do the same work whatever the number of directions or "
        "whether it is timed: no shortcuts for large batches, no results kept "
        "from earlier calls."),
    ),
    DiagnosisInfo(
        "fetch-not-returned", "mapping", ("checks.fetch_sweep",),
        N_("fetchColor does not return the colour readTexture gives it"),
        N_("The grader watched every readTexture call your fetchColor makes and "
        "answered each with a colour of its own: fetchColor returned something "
        "else (a changed, mixed or made-up colour, or black)."),
        N_("Return readTexture's answer unchanged: `return readTexture(faceAddress(face), u, v);`."),
    ),
    DiagnosisInfo(
        "asks-otherwise", "mapping", ("checks.fetch_sweep",),
        N_("fetchColor asks for other texels depending on who answers readTexture"),
        N_("The grader records every readTexture call your fetchColor makes twice: "
        "answered by your own readTexture, and answered with colours of its own. "
        "fetchColor made different calls (or, reading texels itself, returned "
        "different colours) in the two, so what it asks for cannot be judged and "
        "those directions count as wrong."),
        N_("fetchColor must compute its face and (u, v) from the direction alone and "
        "call readTexture once with them, whatever readTexture answers."),
    ),
    DiagnosisInfo(
        "address-not-face-start", "mapping", ("checks.fetch_sweep",),
        N_("fetchColor passes readTexture an address where no face starts"),
        N_("readTexture expects the first texel of one face (docs/assignment.md: face k "
        "starts k * W * H * 3 floats into the buffer). Your fetchColor passed an "
        "address inside a face, or outside the buffer."),
        N_("Pass faceAddress(face) (or m_Texels + face * m_FaceWidth * m_FaceHeight * 3): "
        "the face's first texel, nothing added for u or v."),
    ),
    DiagnosisInfo(
        "fetch-depends-on-the-map", "mapping", ("checks.instruments.map_probe",),
        N_("fetchColor answers otherwise on the public maps"),
        N_("The grader took directions from the arrows' and renders' lookups on "
        "the maps in Cubemap/, asked your fetchColor the same directions on "
        "random faces of the same size in a fresh process, recording which face "
        "and (u, v) it asks readTexture for there, and called your readTexture on "
        "the public map at that face and (u, v). Code whose answers depend on the "
        "direction and the face size alone gives the same colour both ways, right "
        "or wrong. Yours answered otherwise on a public map (the details give the "
        "lookup, one direction and the numbers): what it does depends on the "
        "map's texels, on what readTexture answers or on earlier calls. The checks "
        "that look at the public maps (arrows, renders) were judged again with "
        "what your fetchColor asks for on random faces of each map's size, read "
        "from the public maps as the handout's readTexture reads; the lower score "
        "counts."),
        N_("Compute the face and (u, v) from the direction alone and return "
        "readTexture's answer as it comes: do not use `m_FaceWidth`, "
        "`m_FaceHeight`, the texels or earlier calls in fetchColor."),
    ),
    DiagnosisInfo(
        "texture-context-dependent", "filtering", ("checks.instruments.fetch_record",),
        N_("Your readTexture answers fetchColor differently from other callers"),
        N_("The grader recorded the readTexture calls your fetchColor makes, with "
        "your readTexture's answers, and made the same calls directly: some were "
        "answered differently. The renders use the answers fetchColor gets, so "
        "the readTexture check counts at most the calls answered alike."),
        N_("readTexture must compute the same thing whoever calls it and whatever "
        "the faces' size: no separate paths."),
    ),
    DiagnosisInfo(
        "timing-faces-wrong", "speed", ("checks.speed",),
        N_("Your lookup is wrong on the faces the speed check times"),
        N_("On the speed check's large smooth faces, fetchColor's answers are "
        "right (what your own readTexture gives at the handout's face and "
        "(u, v)) far less often than in the sweep, so the time measured is not "
        "the time of a working lookup and does not count."),
        N_("fetchColor must do the same work whatever the faces' size or colours: "
        "no cheaper path for large faces."),
    ),
    DiagnosisInfo(
        "refused-source", "build", ("build",),
        N_("Your code uses something a submission may not"),
        N_("A submission needs no inline assembly (asm, __asm__), no #line or "
        "line markers, no _Pragma and no pragmas beyond a few harmless ones "
        "(GCC diagnostic, GCC unroll, GCC ivdep, pack, omp, STDC), and no "
        "attributes that write into the assembly or change code generation "
        "(section, alias, weakref, symver, ifunc, target, target_clones, "
        "optimize, fentry_name, fentry_section, patchable_function_entry). "
        "The grader decides on the compiler's own preprocessed tokens, so "
        "macros, digraphs or strings split in pieces do not change the "
        "verdict. The message names the line."),
        N_("Write fetchColor and readTexture in plain C++: remove the asm, #line, "
        "_Pragma, pragma or attribute on that line."),
    ),
]

# Old ids still understood (the student kit's self-check emits them until it
# is rebuilt): each reads as its new entry. "not-normalized" told students who
# did normalise that they had not; what is missing is the division by m.
ALIASES = {"not-normalized": "not-divided-by-m"}

CATALOGUE: dict[str, DiagnosisInfo] = {e.id: e for e in _ENTRIES}
CATALOGUE.update({old: CATALOGUE[new] for old, new in ALIASES.items()})

# What other mistakes cause: reported only when no cause was found, so a
# student reads "u runs the wrong way on +X", not that plus four symptoms.
CONSEQUENCES = frozenset({"render-mismatch", "discontinuous-seam", "arrow-wrong", "arrow-missing"})
# State kept between calls (grader.grading.grade.drop_consequences): explains
# the reads outside the face that other checks meet after faces of another size.
STATE_CAUSES = frozenset({"kept-between-calls", "address-not-face-start"})
_ORDER = {e.id: i for i, e in enumerate(_ENTRIES)}
_ORDER.update({old: _ORDER[new] for old, new in ALIASES.items()})


class UnknownDiagnosis(KeyError):
    """An id that is not in the catalogue: the grader's mistake, never shown
    to a student as made-up words (the check runner turns a check that emits
    one into a harness error; tests/unit/grading/test_diagnosis_catalogue.py finds them
    before that)."""


def describe(diagnosis_id: str) -> DiagnosisInfo:
    """The catalogue entry for an id."""
    try:
        return CATALOGUE[diagnosis_id]
    except KeyError:
        raise UnknownDiagnosis(f"diagnosis id {diagnosis_id!r} is not in grader/grading/catalogue.py") from None


def sort_key(diagnosis_id: str) -> tuple[int, str]:
    """Catalogue order (what stops grading first)."""
    describe(diagnosis_id)
    return (_ORDER[diagnosis_id], diagnosis_id)


def catalogue_markdown() -> str:
    """docs/diagnoses.md, generated from the table above."""
    lines = [
        "# Diagnoses",
        "",
        "<!-- Generated by `python -m grader.grading.catalogue > docs/diagnoses.md` from",
        "     grader/grading/catalogue.py; edit that file, not this one. -->",
        "",
        "Each mistake the grader recognises has a stable id. Reports show it in",
        "plain words with what to do about it; `results.json` lists it under",
        '`extra_data.diagnoses` as `{"id": ..., "face": ..., "detail": ...}`',
        "(`face` only where it applies). Conventions are those of",
        "`docs/assignment.md`.",
        "",
    ]
    for kind, heading in KINDS.items():
        entries = [e for e in _ENTRIES if e.kind == kind]
        lines += [f"## {heading}", ""]
        for e in entries:
            lines += [
                f"### `{e.id}`: {e.title}",
                "",
                e.explanation,
                "",
                f"**What to do:** {e.what_to_do}",
                "",
            ]
    return "\n".join(lines).rstrip("\n") + "\n"


if __name__ == "__main__":
    print(catalogue_markdown(), end="")
