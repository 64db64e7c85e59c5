"""Grading one submission: the checks run, scored against the rubric, gathered into results;
the diagnosis catalogue and the fixtures they compare with."""
