"""Motion data: skeletons, motions, BVH I/O, body-part mapping and clip libraries (no MuJoCo)."""
