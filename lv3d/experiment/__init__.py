"""The experiment runner: study configs, folds, the systems compared, statistics and the report."""
