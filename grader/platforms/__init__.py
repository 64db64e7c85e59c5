"""The platforms courses grade on: Gradescope (autograder.zip) and
PrairieLearn (an external-grader image). Each turns one grading
(grader.grading.grade) into that platform's results.json and knows how the platform
lays out its files; neither grades anything itself."""
