"""Readers and writers: the recording folder, joint tables, motion-capture files."""
