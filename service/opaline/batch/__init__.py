"""Batch thumbnails: planning, worker pools, the remote client, progress, sheets."""
