r"""Ensembles: many samples of one deck on Dask distributed.

``sphdyn ensemble DECK --samples N [--vary key=v1,v2,...] [--scheduler ADDR]``
runs N random samples of a deck (for each point of the ``--vary`` grid) as
independent tasks on a Dask cluster: a :class:`distributed.LocalCluster` of
worker *processes* by default, or any running scheduler (so the same command
scales to a batch system through dask-jobqueue or to MPI through dask-mpi).

Layout of the output directory ``OUT`` (default ``out/<deck>-ensemble``)::

    OUT/ensemble.json             the plan: deck, overrides, grid, seeds
    OUT/sample_0000/              one directory per sample: a normal run
        deck.resolved.toml        directory (frames, history, summary.json)
        result.json               written last and atomically: the marker
        plots/mass_histogram.png  the mass field's histogram (paper Fig. 5)
    OUT/ensemble.csv              one row per sample (see :data:`COLUMNS`)
    OUT/ensemble_damage.png       final damage of every sample (paper Figs. 8-10)

Seeds. Sample ``s`` of every grid point gets the run seed
:func:`sample_seed` (base seed, s) with the base seed the deck's
``run.seed``; so the grid points share their random fields (common random
numbers: a kappa study compares the same mass fields). Everything a sample
does is a function of its resolved deck, so results do not depend on the
number of workers or on the order in which they finish.

Resuming. A sample whose ``result.json`` says ``completed`` for the same
overrides is skipped; any other sample (never started, interrupted, failed)
is run again from scratch in its directory. A failing sample (invalid deck,
a guard stopping the run, an exception, a lost worker) is recorded with its
error and does not stop the others.

Workers. Each sample is one task on a one-thread Dask worker; the Numba
threads of a sample are ``cores // workers``. The default is one worker per
core with one Numba thread each (pair loops scale by only 1.45-1.6x from 1 to
2 threads here, see BENCHMARKS.md, so independent samples use the cores
better), or fewer workers with more threads when there are fewer samples
than cores.

Modules: :mod:`.plan` (seeds, ``--vary``, :class:`SampleSpec`),
:mod:`.run` (one sample, the Dask runner), :mod:`.metrics` (scalar results,
main cracks) and :mod:`.report` (table, damage grid, mass histograms).
"""

from __future__ import annotations

from .metrics import FAILED_DAMAGE, count_main_cracks, sample_metrics
from .plan import PLAN, RESULT, SampleSpec, parse_vary, plan_samples, sample_seed
from .report import (COLUMNS, FIGURE, TABLE, plot_damage_grid, plot_mass_histograms,
                     write_report)
from .run import default_layout, run_ensemble, run_sample

__all__ = ["COLUMNS", "FAILED_DAMAGE", "FIGURE", "PLAN", "RESULT", "SampleSpec", "TABLE",
           "count_main_cracks", "default_layout", "parse_vary", "plan_samples",
           "plot_damage_grid", "plot_mass_histograms", "run_ensemble", "run_sample",
           "sample_metrics", "sample_seed", "write_report"]
