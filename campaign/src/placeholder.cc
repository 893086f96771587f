// Placeholder translation unit until the campaign sources land.
