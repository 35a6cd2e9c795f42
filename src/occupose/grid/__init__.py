"""Stage 1 and 2: the occupancy grid with a per-cell HMM and camera visibility, and people
as labelled, tracked blobs of moving cells."""
