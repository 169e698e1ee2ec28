"""What the scripts read of a log fit (log_fit.json, learned_fit.json): the methods its logs are
scored by, as their `mae_deg` keys name them, and the mean error per motor. report.py and
docs_numbers.py use it.

Imported from the scripts' folder (Python puts a script's own folder first on its path).
"""

# identify's methods (log_fit.json's `mae_deg` keys) with their names for a table, in the
# order of the ladder: no model, the best time shift in hindsight, the paper's, the extended.
METHODS = (("direct", "direct"), ("best_shift", "best shift"), ("paper", "paper"),
           ("extended", "extended"))

# The networks learned_fit.py adds to each log's `mae_deg` in learned_fit.json.
LEARNED = (("mlp", "mlp"), ("lstm", "lstm"))


def logs_of(fit, role):
    """The logs of `fit` (a parsed log_fit.json or learned_fit.json) with `role`: "validate"
    (each scored by the models of the fold that held it out) or "train" (by the final
    models, fitted on every log)."""
    return [log for log in fit.get("logs", []) if log.get("role") == role]


def mean_errors(logs, keys):
    """{motor: {key: mean of mae_deg[key] over that motor's logs}} and {motor: their count}."""
    sums, counts = {}, {}
    for log in logs:
        motor = log["motor"]
        counts[motor] = counts.get(motor, 0) + 1
        row = sums.setdefault(motor, dict.fromkeys(keys, 0.0))
        for key in keys:
            row[key] += float(log["mae_deg"][key])
    means = {motor: {key: total / counts[motor] for key, total in row.items()}
             for motor, row in sums.items()}
    return means, counts
