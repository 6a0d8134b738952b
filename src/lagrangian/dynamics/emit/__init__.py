"""The C text of the tree recursions (an emitter of named terms), shared by the compiled engine and
the standalone export."""
