"""Shared layer of the project, its ground floor: the contract every model and tool meets.

- scenes: :mod:`sandwich.scene` (types, vocabularies, defaults), :mod:`sandwich.scene_checks`
  (validation), :mod:`sandwich.scene_file` (``load_scene``);
- results: :mod:`sandwich.results` (types, writers, readers, a result's identity);
- the generic path-following solver: :mod:`sandwich.solver`; a progress display.

Every model (``sandwich.beam``, ``sandwich.meshes`` + ``sandwich.plane2d``) and tool above them may
import this
package; it imports no model, no registry, no comparison, no command line
(``tests/test_layers.py``).
"""
