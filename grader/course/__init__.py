"""The course: grading a class, its roster, copied solutions, and the audit of the grader itself."""
