"""Infrastructure every room may use: errors, atomic writes, JSON/CSV helpers, option
parsers and where the package's resources (shaders, fabrics, data) are. Imports nothing heavy."""
