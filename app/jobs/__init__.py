"""Work off the GUI thread: the job runner and its controls, the analysis and model-lab workers, the cycle collector's place."""
