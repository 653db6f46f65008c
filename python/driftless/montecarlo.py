"""The experiment of ``driftless experiment`` (Allan analysis → noise model, chamber →
thermal model, a vehicle run processed raw, with room biases, with the full room
calibration and with the thermal model, GNSS outages, Monte Carlo repetitions) from
Python, whole or one run at a time.

``driftless.experiment(scenario)`` runs it all in this process (the runs in parallel
threads) like the CLI. For many processes or machines (Dask, multiprocessing, a batch
queue) the three functions here are pure and their arguments and results picklable:

* ``prepare(scenario)`` checks the scenario (cheap: no noise or vehicle stage) and
  returns a ``Plan`` — the scenario text, its number of runs, seed and outage windows;
* ``run_one(scenario_text, run_index)`` computes run ``run_index`` and returns one flat
  row (a dict of numbers, text and flags). A run's random draws come from the scenario
  seed and the run index alone (the library's ``run_seed``), so a row is the same
  whichever process computes it, and the same as that run of the serial experiment. A
  process builds the shared noise stage once and reuses it for the scenario's runs;
* ``summarise(rows, scenario)`` turns the rows of runs 0…K−1 (any order) into the
  experiment's statistics, the same numbers the serial experiment reports.

Row columns: ``run``; ``temperature_start_c``, ``temperature_end_c``; and per processed
case — prefix ``raw`` (a), ``room_bias`` (b), ``thermal`` (c), ``room_full`` (d) —
``{case}_forward_failure`` (why the filter failed; empty when it ran),
``{case}_forward_mean_end_m`` (the run's mean end-of-outage horizontal error, m),
``{case}_forward_end_m_{k}`` (outage k = 1…N), the same three for ``smoothed``,
``{case}_smoothed`` (whether this run was smoothed), ``{case}_gnss_accepted``,
``{case}_gnss_rejected``. Missing numbers are NaN.
"""

import json
import os

import numpy as np

from . import _driftless

__all__ = ["Plan", "prepare", "run_one", "summarise", "builtin_scenario", "Summary",
           "ExperimentResult", "experiment", "rows_to_columns"]


def builtin_scenario():
    """The TOML text of the built-in ``adi-like`` scenario (``driftless demo``)."""
    return _driftless.experiment_builtin_scenario()


def _source(scenario):
    """(text, name, base folder) of a scenario given as a Plan, a path or TOML text."""
    if isinstance(scenario, Plan):
        return scenario.text, scenario.name, scenario.base_dir
    if isinstance(scenario, os.PathLike) or (
            isinstance(scenario, str) and "\n" not in scenario and "=" not in scenario):
        path = os.fsdecode(scenario)
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except OSError as e:
            raise ValueError(f"{path}: cannot read the scenario: {e.strerror}") from None
        return text, path, os.path.dirname(os.path.abspath(path))
    if not isinstance(scenario, str):
        raise ValueError(f"scenario must be TOML text, a path or a Plan, got {type(scenario).__name__}")
    return scenario, "<scenario>", os.getcwd()


class Plan:
    """A checked scenario, ready to be run (picklable): ``text``, ``name`` (used in
    messages), ``base_dir`` (relative paths in the scenario resolve against it),
    ``runs`` (``[monte_carlo] runs``), ``seed``, ``outages`` (the windows, GPS s)."""

    def __init__(self, text, name, base_dir, raw):
        self.text = text
        self.name = name
        self.base_dir = base_dir
        self.runs = raw["runs"]
        self.seed = raw["seed"]
        self.outages = [tuple(w) for w in raw["outages"]]

    def run_one(self, run_index):
        """``run_one`` of this plan's scenario."""
        return run_one(self, run_index)

    def summarise(self, rows):
        """``summarise`` with this plan's scenario."""
        return summarise(rows, self)

    def __repr__(self):
        return f"Plan(name={self.name!r}, runs={self.runs}, seed={self.seed}, outages={len(self.outages)})"


def prepare(scenario):
    """Check a scenario (TOML text, a path, or a ``Plan``) and fix its outage windows,
    without running any stage; returns a ``Plan``. A wrong scenario raises
    ``ValueError`` naming the key."""
    text, name, base = _source(scenario)
    return Plan(text, name, base, _driftless.montecarlo_prepare(text, name, base))


def run_one(scenario, run_index):
    """Run ``run_index`` (0 = the detailed run) of a scenario (TOML text, a path or a
    ``Plan``) as one flat row (module docs). Deterministic: the same row for the same
    scenario and index in any process."""
    if isinstance(run_index, bool) or not isinstance(run_index, (int, np.integer)) or run_index < 0:
        raise ValueError(f"run_index must be a whole number ≥ 0, got {run_index!r}")
    text, name, base = _source(scenario)
    return _driftless.montecarlo_run_one(text, name, base, int(run_index))


class Summary:
    """Statistics over the runs: ``runs``; ``cases`` — per case its label, the spread
    (``n``, ``mean``, ``p5``, ``p50``, ``p95``, m) of the per-run mean end-of-outage
    horizontal error of the forward filter (``forward_mean_end_m``) and of the smoothed
    solution, failed runs; the ratios (b)/(c) and (d)/(c) with their bootstrap intervals;
    the reversal counts. ``to_dict()`` is the library's serialised form; ``columns()``
    the per-case table (case, mean/p5/median/p95 in m, failed runs) as columns."""

    def __init__(self, raw):
        self._dict = json.loads(raw["summary_json"])
        self._header = list(raw["summary_header"])
        self._rows = [list(r) for r in raw["summary_rows"]]
        self.runs = self._dict["runs"]
        self.cases = self._dict["cases"]
        self.ratio_room_over_thermal = self._dict.get("ratio_room_over_thermal")
        self.ratio_full_room_over_thermal = self._dict.get("ratio_full_room_over_thermal")

    def to_dict(self):
        return json.loads(json.dumps(self._dict))

    def columns(self):
        """The per-case table: ``case`` (label), ``mean_m``, ``p5_m``, ``median_m``,
        ``p95_m`` (NaN where the case never finished), ``failed_runs``."""
        cols = {"case": [], "mean_m": [], "p5_m": [], "median_m": [], "p95_m": [], "failed_runs": []}
        for c in self.cases:
            s = c.get("forward_mean_end_m") or {}
            cols["case"].append(c["label"])
            for key, field in (("mean_m", "mean"), ("p5_m", "p5"), ("median_m", "p50"), ("p95_m", "p95")):
                cols[key].append(s.get(field, float("nan")))
            cols["failed_runs"].append(c["failed_runs"])
        return {k: (np.array(v) if k != "case" else v) for k, v in cols.items()}

    def table(self):
        """The table ``driftless experiment`` prints (text)."""
        widths = [max(len(str(r[i])) for r in [self._header] + self._rows)
                  for i in range(len(self._header))]
        line = lambda r: "  ".join(str(v).rjust(w) for v, w in zip(r, widths))
        return "\n".join([line(self._header)] + [line(r) for r in self._rows])

    def __eq__(self, other):
        return isinstance(other, Summary) and json.dumps(self._dict, sort_keys=True) == json.dumps(
            other._dict, sort_keys=True)

    def __repr__(self):
        return f"Summary(runs={self.runs}, cases={[c['label'] for c in self.cases]})"


def summarise(rows, scenario):
    """The experiment's statistics (a ``Summary``) from the rows of runs 0…K−1 (any
    order; each once) of ``scenario`` (TOML text, path or ``Plan``: its confidence level
    and seed fix the bootstrap)."""
    text, name, base = _source(scenario)
    rows = [dict(r) for r in rows]
    return Summary(_driftless.montecarlo_summarise(text, name, base, rows))


def rows_to_columns(rows):
    """Rows (dicts with the same keys) as columns: a dict of NumPy arrays (text columns
    as lists) that ``pandas.DataFrame`` takes, sorted by ``run``."""
    rows = sorted(rows, key=lambda r: r["run"])
    if not rows:
        return {}
    out = {}
    for key in rows[0]:
        values = [r[key] for r in rows]
        out[key] = values if isinstance(values[0], str) else np.array(values)
    return out


class ExperimentResult:
    """The whole experiment: ``rows`` (one flat row per run, as ``run_one`` returns
    them), ``summary`` (a ``Summary``), ``columns()`` (the per-run table as columns),
    ``to_dict()`` (the JSON document of ``driftless experiment --json``: scenario, noise
    model, thermal model, Table 1 of run 0, outages, summary)."""

    def __init__(self, raw):
        self.rows = list(raw["rows"])
        self.summary = Summary(raw)
        self._document = raw["document_json"]

    def columns(self):
        return rows_to_columns(self.rows)

    def to_dict(self):
        return json.loads(self._document)

    def __repr__(self):
        return f"ExperimentResult(runs={len(self.rows)}, summary={self.summary!r})"


def experiment(scenario, *, runs=None):
    """Run the whole experiment of a scenario (TOML text or a path), as ``driftless
    experiment SCENARIO`` (the runs in parallel threads, the GIL released); ``runs``
    overrides ``[monte_carlo] runs``. Returns an ``ExperimentResult``."""
    if runs is not None and (isinstance(runs, bool) or not isinstance(runs, (int, np.integer)) or runs < 1):
        raise ValueError(f"runs must be a whole number ≥ 1, got {runs!r}")
    text, name, base = _source(scenario)
    return ExperimentResult(_driftless.experiment_run(text, name, base, None if runs is None else int(runs)))
