"""The student kit: what students receive (`python -m grader kit`,
`make student-kit`; build.py assembles it).

The kit holds no implementation of the lookup: reference/src/lookup.c stays
out, and the kit's envmap.h has the lookup declarations cut out
(build.HEADER_CUTS; the reference header itself is unchanged, so the
fixtures that hash it stay valid). Its self-check is the grader itself: the
`grader` modules the self-check's entry point (selfcheck.py) imports, copied
into the kit's selfcheck/ folder with the files they read, laid out as in
the checkout. It grades the student's EnvironmentMap.cpp with
grader.grading.grade.grade(): the same build, worker, checks, scoring and reports.
What differs is only where the lookup's answers come from: recorded at
kit-build time on the kit's fixed public inputs (answers.py,
grader.envmap.oracle.Replay) instead of the live C reference. No hidden check, no
secret, no secret-seeded input; speed is left out (it times the reference).
"""

# The kit's inputs are public: one fixed seed, unrelated to the course secret.
KIT_SEED = 20261201
# The reference's recorded answers, in the kit's copy of the checkout (selfcheck/).
ANSWERS = "reference_answers.npz"
# Checks the kit cannot run, whatever the rubric says, and why.
NOT_IN_KIT = {"speed": "the speed verdict needs the grader's reference timing on a quiet machine"}
