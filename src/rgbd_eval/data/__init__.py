"""Data files shipped with the package (models, with their licences)."""
