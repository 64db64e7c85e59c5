"""What the checks share to measure a submission: instruments, not checks
(grader.checks holds one module per rubric entry; these are used by several)."""
