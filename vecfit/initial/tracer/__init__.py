"""Tracing: raster image -> initial vector graphic (see trace.py for the pipeline)."""
from .trace import TraceResult, TraceSettings, trace_image

__all__ = ["TraceResult", "TraceSettings", "trace_image"]
