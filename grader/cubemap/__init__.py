"""Environment maps: the test map and generated environments (Cubemap/), the
converters between lat-long, angular and vertical-cross maps, and the
handout's lost figures. `python -m grader cubemap` is the front door
(grader/commands/cubemap.py); docs/cubemap.md describes the maps.
"""
