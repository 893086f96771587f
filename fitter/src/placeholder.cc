// Placeholder translation unit until the fitter sources land.
