"""The thesis authors' trained people classifier (PCL people module, BSD): see README.md."""
