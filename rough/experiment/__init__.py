"""The perception experiment: paired comparisons of fractal surfaces felt through the
haptic renderer, and their analysis.

The modules: :mod:`rough.experiment.design` (reference surfaces and their
neighbours on a (D, Rq) grid, the randomised trial list, written to a study folder),
:mod:`rough.experiment.session` (running a subject's session on the joystick or the
simulated hand, each answer saved at once), :mod:`rough.experiment.observer` (a
scripted observer for headless sessions) and :mod:`rough.experiment.analysis`
(multiple logistic regression of the answers on ΔD, ΔRq and subject, with the
paper's Wald statistics). SI units, except that Rq differences enter the analysis in
millimetres.

A whole study, headless: design, simulated sessions, analysis.

>>> import pathlib, tempfile
>>> from rough.experiment.analysis import answers_table, fit
>>> from rough.experiment.design import grid_design, write_study
>>> from rough.experiment.observer import parse_observer
>>> from rough.experiment.session import run_session, simulated_presenter
>>> from rough.render import QuasiStatic, Settings
>>> surfaces, sets = grid_design([(1.275, 0.2781e-3)], dimension_step=0.075, rq_factor=1.2593)
>>> folder = tempfile.TemporaryDirectory()
>>> study = write_study(pathlib.Path(folder.name) / "study", surfaces, sets, ["S01", "S02", "S03"], 5, 4e-3, 30.9e-6,
...                     0.1545e-3)
>>> observer = parse_observer("rq=12,dimension=-4,seed=7")
>>> present = simulated_presenter(study, observer, 0.02, QuasiStatic(), None, Settings(realtime=False))
>>> for subject in study.subjects:
...     print(run_session(study, subject, present, "sim"))
Progress(answered=8, remaining=0, total=8, interrupted=False)
Progress(answered=8, remaining=0, total=8, interrupted=False)
Progress(answered=8, remaining=0, total=8, interrupted=False)
>>> analysis = fit(answers_table(study), study.subjects)
>>> analysis.n, list(analysis.coefficients)
(24, ['fractal_dimension', 'rq', 'subject_S02', 'subject_S03', 'constant'])
>>> folder.cleanup()
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
