"""Solid shape primitives, ray casting and angles, shared by the scene renderer, the body model and the likelihoods."""
