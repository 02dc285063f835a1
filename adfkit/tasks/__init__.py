"""Tasks played on a SimWorld: the scripted suture (suture.py), its metrics (metrics.py) and
the episode runner that writes metrics, pictures and a dataset (episode.py); drilling a voxel
volume with a burr in a room of its own (drilling/).

Task code talks to SimWorld's public methods and adfkit.runner.psm.PSM only (engine-neutral)."""
