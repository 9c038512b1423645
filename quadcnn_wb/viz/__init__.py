"""Pictures of every pipeline stage (matplotlib, no screen needed), like the paper's figures."""
