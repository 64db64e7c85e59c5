"""The student kit: what students receive (`python -m grader kit`,
`make student-kit`; build.py assembles it, data.py computes its data).

The kit is generated from student_template/ and reference/ and holds no
implementation of the lookup: reference/src/lookup.c stays out, and the
kit's envmap.h has the lookup declarations cut out (build.HEADER_CUTS; the
reference header itself is unchanged, so the fixtures that hash it stay
valid). Its self-check (student_template/selfcheck/) is a C++ driver
compiled with the student's EnvironmentMap.cpp plus a standard-library-only
Python script that compares the driver's outputs with data computed here by
the grader's reference on public inputs, and names mistakes by comparing
with the outputs each known mistake gives on those inputs. It scores the
checks the rubric marks visible, with the rubric's points, except the speed
check (grader-only). No hidden check, no secret, no secret-seeded input.

Measured on the 2-core development machine, December 2026 (quiet / loaded
by six other sessions):
  - the zip is 2.1 MB (5.3 MB unpacked: 1.3 MB of maps, 3.6 MB of data);
    building it takes 1-5 s;
  - set-up: none (no virtual environment, no download, nothing but python3,
    a C++17 compiler and make); `make selfcheck` cold (compiling the
    renderer, the driver and the student's file) 3.2 s / 11 s, warm
    0.4 s / 1.6 s; build/ is 2.8 MB afterwards;
  - `make run` (512x512, 16 spp) 1.4 s / 6 s; out.png 117 KB for a correct
    solution, 7.7 KB for the black start (the old stored-deflate writer
    wrote 787 KB).
"""
