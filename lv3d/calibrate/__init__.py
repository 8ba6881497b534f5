"""Making the confidence calibration maps lv3d ships (lv3d/data/calibration.json, read by lv3d.calibration):
``lv3d calibrate rows|real|fit|check``.

| module | what |
|---|---|
| ``rows`` | candidate facts of perceived rendered dev scenes with their truth (``lv3d calibrate rows``) |
| ``real`` | labelled ``perpendicular`` candidates of real frames; bench_real's box figures for any maps |
|          | (``lv3d calibrate real``) |
| ``fit`` | the fit of the maps, its checks and the file's provenance (``lv3d calibrate fit``; its docstring |
|         | holds the whole recipe) |
| ``check`` | per-type ECE of the shipped maps on rendered rows (``lv3d calibrate check``) |
| ``measures`` | ECE, its chance level and scene interval, log loss |
| ``truth`` | the truth of rendered candidates: which perceived face is which true face |

Nothing at run time imports this package: describe() reads the maps through lv3d.calibration alone.
"""
