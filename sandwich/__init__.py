"""Shared layer of the project: scenes, result types and writers, the generic path-following solver.

Every model (``beam_element``, ``meshes`` + ``reference2d``) may import this package; it imports no
model.
"""
