"""Synthetic RGB-D scenes with ground truth: motion, body shapes, furniture, rendering, noise."""
