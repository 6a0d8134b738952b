"""The numpy reference recursions over a tree, one family per file."""
