"""Rendering a whole catalog: every fabric x light x frame x yaw, resumable, on one process
or spread over Dask workers (docs/batch.md).

>>> from catalog.batch import JobSpec, render_catalog        # doctest: +SKIP
>>> spec = JobSpec.create(fabrics="lace-fwa,linen-dense", lights="D65,A", frames="0:48:12",
...                       size="320x240", image_format="png", out_dir="out/catalog")
>>> summary = render_catalog(spec, workers=4)                 # doctest: +SKIP
"""

from catalog.batch.engine import check_engine, render_catalog
from catalog.batch.spec import FabricTask, ImageJob, JobSpec, parse_frames, parse_yaws
from catalog.batch.worker import render_fabric

__all__ = ["FabricTask", "ImageJob", "JobSpec", "check_engine",
           "parse_frames", "parse_yaws", "render_catalog", "render_fabric"]
