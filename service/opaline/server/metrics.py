"""Prometheus metrics, on a registry of the app's own (never the global one).

One ``Metrics`` per app, so two apps in one process (tests) do not share or
collide on counters.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping

from prometheus_client import (
    CONTENT_TYPE_LATEST,
    CollectorRegistry,
    Counter,
    Gauge,
    Histogram,
    generate_latest,
)
from prometheus_client.core import CounterMetricFamily
from prometheus_client.registry import Collector

# Render times on llvmpipe run from milliseconds (draft thumbnails) to tens of
# seconds (reference tier at 2048²).
RENDER_BUCKETS = (0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0, 30.0, 60.0)

REJECT_REASONS = ("invalid", "malformed", "unknown_preset", "not_found", "method_not_allowed",
                  "cost", "too_slow", "too_large", "queue_full", "deadline", "unavailable",
                  "cancelled", "forbidden", "rate_limited", "timeout", "render_failed", "error", "limit",
                  "unknown_mesh", "invalid_mesh", "unknown_environment", "unknown_turntable",
                  "rendering", "busy", "budget_with_tier", "store_unavailable",
                  "unsupported_media_type")
# The worker pool's own counters, exported as they stand at scrape time.
POOL_COUNTERS = {
    "restarts_crash": ("opaline_worker_restarts", "Worker processes replaced, by reason.",
                       {"reason": "crash"}),
    "restarts_died": ("opaline_worker_restarts", "", {"reason": "died"}),
    "restarts_watchdog": ("opaline_worker_restarts", "", {"reason": "watchdog"}),
    "render_failures": ("opaline_render_failures", "Renders that raised (answered 500).", {}),
    "context_restarts": ("opaline_context_restarts",
                         "GL contexts released after a failure and made anew.", {}),
    "recycles": ("opaline_worker_recycles", "Workers recycled after max renders or memory.", {}),
    "watchdog_kills": ("opaline_watchdog_kills", "Renders killed past the time limit.", {}),
    "program_evictions": ("opaline_worker_cache_evictions", "Worker cache evictions.",
                          {"cache": "program"}),
    "scene_evictions": ("opaline_worker_cache_evictions", "", {"cache": "scene"}),
    "target_evictions": ("opaline_worker_cache_evictions", "", {"cache": "target"}),
    "refused_too_slow": ("opaline_admission_refusals", "Jobs refused at admission, by reason.",
                         {"reason": "too_slow"}),
    "refused_queue": ("opaline_admission_refusals", "", {"reason": "queue"}),
    "expired": ("opaline_jobs_expired", "Queued jobs dropped when their deadline passed.", {}),
    "cancelled": ("opaline_jobs_cancelled", "Queued jobs dropped when every client left.", {}),
}


class Metrics:
    """The service's instruments."""

    content_type = CONTENT_TYPE_LATEST

    def __init__(self) -> None:
        self.registry = CollectorRegistry(auto_describe=True)
        self.render_seconds = Histogram(
            "opaline_render_seconds", "Time a worker spent rendering and encoding one image.",
            ["preset"], buckets=RENDER_BUCKETS, registry=self.registry)
        self.queue_depth = Gauge(
            "opaline_queue_depth", "Jobs waiting for a render worker.", registry=self.registry)
        self.cache_hits = Counter(
            "opaline_cache_hits", "Image requests answered from the cache.",
            registry=self.registry)
        self.cache_misses = Counter(
            "opaline_cache_misses", "Image requests that needed a render.",
            registry=self.registry)
        self.cache_bytes = Gauge(
            "opaline_cache_bytes", "Bytes of encoded images held in the cache.",
            registry=self.registry)
        self.rejected = Counter(
            "opaline_rejected_requests", "Requests refused, by reason.", ["reason"],
            registry=self.registry)
        for reason in REJECT_REASONS:
            self.rejected.labels(reason)

    def watch(self, queue_depth: Callable[[], float], cache_bytes: Callable[[], float]) -> None:
        """Read the gauges from their sources at scrape time."""
        self.queue_depth.set_function(queue_depth)
        self.cache_bytes.set_function(cache_bytes)

    def watch_pool(self, counters: Mapping[str, int], image_evictions: Callable[[], int]) -> None:
        """Export the pool's counters (a mapping it keeps up to date) and the image cache's
        evictions at scrape time."""
        self.registry.register(_PoolCollector(counters, image_evictions))

    def watch_connections(self, stats: Mapping[str, int]) -> None:
        """Export the connection layer's refusals and timeouts (opaline.server.connections)."""
        self.registry.register(_ConnectionCollector(stats))

    def reject(self, reason: str) -> None:
        self.rejected.labels(reason).inc()

    def exposition(self) -> bytes:
        return generate_latest(self.registry)


class _PoolCollector(Collector):
    def __init__(self, counters: Mapping[str, int], image_evictions: Callable[[], int]) -> None:
        self.counters, self.image_evictions = counters, image_evictions

    def collect(self) -> Iterator[CounterMetricFamily]:
        families: dict[str, CounterMetricFamily] = {}
        for key, (name, doc, labels) in POOL_COUNTERS.items():
            family = families.get(name)
            if family is None:
                family = families[name] = CounterMetricFamily(name, doc, labels=list(labels))
            family.add_metric(list(labels.values()), self.counters.get(key, 0))
        yield from families.values()
        images = CounterMetricFamily("opaline_image_cache_evictions",
                                     "Images evicted from the HTTP process's cache.")
        images.add_metric([], self.image_evictions())
        yield images


class _ConnectionCollector(Collector):
    def __init__(self, stats: Mapping[str, int]) -> None:
        self.stats = stats

    def collect(self) -> Iterator[CounterMetricFamily]:
        refused = CounterMetricFamily("opaline_connections_refused",
                                      "Connections refused at once, by cap.", labels=["cap"])
        for cap in ("connections", "per_client"):
            refused.add_metric([cap], self.stats.get("refused_" + cap, 0))
        malformed = CounterMetricFamily("opaline_malformed_http",
                                        "Requests that were not valid HTTP/1.1 (answered 400).")
        malformed.add_metric([], self.stats.get("malformed", 0))
        yield malformed
        timeouts = CounterMetricFamily("opaline_connection_timeouts",
                                       "Connections closed for a slow client.", labels=["kind"])
        for kind in ("header", "body", "write"):
            timeouts.add_metric([kind], self.stats.get(kind + "_timeouts", 0))
        yield refused
        yield timeouts
