"""Scoring tracks against ground truth (Table I of the first paper), reports and the evaluation runner."""
