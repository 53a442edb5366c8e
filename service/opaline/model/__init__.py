"""The request model and its float64 reference: parameters and ranges, presets,
the merge into a job, material files, the CIE spectrum, sample patterns.
No GL, no HTTP: everything here runs in plain NumPy."""
