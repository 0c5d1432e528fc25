"""The records of a run's results (``designs.json``): their types, and the check of a saved one.

The optimiser writes the record of one design (:mod:`.design`), the study the run's record around it
(:mod:`.run`); the report and the export read them back through :func:`.read.read_run_record`, which checks a
saved ``designs.json`` against these types (:mod:`.checked`). The types are TypedDicts: the records stay the
dicts written to and read from JSON.
"""
