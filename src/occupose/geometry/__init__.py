"""Solid shape primitives and ray casting, shared by the scene renderer and the likelihoods."""
