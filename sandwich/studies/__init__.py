"""Design studies over many cases (``sandwich study``): study files, the Dask engine, the store.

- :mod:`sandwich.studies.study_file`: the study file (base scene, parameters, quantities) and
  its checks;
- :mod:`sandwich.studies.study_run`: the cases on a Dask cluster, each stored by its scene digest;
- :mod:`sandwich.studies.study_report`: the table, the curves and the knock-down map;
- :mod:`sandwich.studies.study`: ``run_study``, the whole study.

Models are reached through the registry (:mod:`sandwich.models`).
"""
