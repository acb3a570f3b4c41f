"""What watches a run without changing its physics.

The run loop (:mod:`sphdyn.simulation`) calls these between steps:

* :mod:`.monitors`: the per-step watchers (guards, history rows and probes,
  frames, checkpoints, the energy guard, progress), one object each;
* :mod:`.guards`: the checks that stop a run with a diagnosis (NaN, time-step
  collapse, particles leaving the domain, the energy error);
* :mod:`.probes`: a deck's ``[[probe]]`` sets reduced to history columns;
* :mod:`.gauges`: LS-DYNA-style node histories and section forces
  (``[[gauge]]``);
* :mod:`.interaction_work`: the work each interaction's forces do, for the
  energy balance;
* :mod:`.threads`: the thread-count tuner;
* :mod:`.interrupt`: Ctrl-C and SIGTERM turned into a clean stop with a
  checkpoint.
"""
