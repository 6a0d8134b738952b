"""Standalone C99 export: a model's dynamics, frames and control laws."""
