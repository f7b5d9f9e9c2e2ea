"""The document-001 quadruped in MuJoCo: its MJCF model and the simulated slope walk."""
