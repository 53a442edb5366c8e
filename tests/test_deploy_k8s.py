"""deploy/k8s: valid for a current Kubernetes, and saying what the service means.

The schemas ship with kubernetes-validate (no network). Beyond the schema, the
manifests must agree with the code: probes with /readyz and /healthz, the memory
limit with the service's memory budget, the user with the images', the grace
period and the cache's timeouts with how long the service lets a request wait.
"""

from __future__ import annotations

import copy
import os
import re
import subprocess
from pathlib import Path
from urllib.parse import urlsplit

import pytest
import yaml

from opaline.server.localproxy import TEMPLATE
from opaline.server.service import Service
from opaline.settings import Settings, memory_budget_bytes
from test_deploy_nginx import need_nginx

# In CI (the test extra installs it) a missing validator is a failure, not a skip.
if os.environ.get("CI"):
    import kubernetes_validate
else:
    kubernetes_validate = pytest.importorskip("kubernetes_validate")
ROOT = Path(__file__).resolve().parent.parent
K8S = ROOT / "deploy" / "k8s"
KUBERNETES = "1.37.0"
MIB = 1024 * 1024


def documents() -> list[dict]:
    return [doc for path in sorted(K8S.rglob("*.yaml"))
            for doc in yaml.safe_load_all(path.read_text()) if doc]


def find(kind: str, name: str) -> dict:
    return next(d for d in documents() if d["kind"] == kind and d["metadata"]["name"] == name)


def container(deployment: dict) -> dict:
    return deployment["spec"]["template"]["spec"]["containers"][0]


def settings_of(deployment: dict) -> Settings:
    env = {e["name"].removeprefix("OPALINE_").lower(): e["value"]
           for e in container(deployment)["env"]}
    return Settings(**env)


def mebibytes(quantity: str) -> int:
    value, unit = re.fullmatch(r"(\d+)(Mi|Gi)", quantity).groups()
    return int(value) * (1024 if unit == "Gi" else 1)


def test_every_manifest_is_valid_for_a_current_kubernetes():
    kinds = set()
    for doc in documents():
        kubernetes_validate.validate(doc, KUBERNETES, strict=True)
        kinds.add(doc["kind"])
    assert kinds == {"Deployment", "Service", "PodDisruptionBudget", "HorizontalPodAutoscaler",
                     "PersistentVolumeClaim", "Job"}


def test_the_validator_catches_a_misspelt_field():
    """Strict validation: a typo is an error, not an ignored field."""
    broken = copy.deepcopy(find("Deployment", "opaline"))
    container(broken)["readinesProbe"] = container(broken).pop("readinessProbe")
    with pytest.raises(kubernetes_validate.ValidationError):
        kubernetes_validate.validate(broken, KUBERNETES, strict=True)


def test_probes_mean_what_the_health_routes_mean():
    """Readiness = a worker can render (/readyz), as the image's HEALTHCHECK; liveness = the
    process answers (/healthz)."""
    opaline = container(find("Deployment", "opaline"))
    assert opaline["readinessProbe"]["httpGet"]["path"] == "/readyz"
    assert opaline["livenessProbe"]["httpGet"]["path"] == "/healthz"
    assert opaline["startupProbe"]["httpGet"]["path"] == "/healthz"
    healthcheck = next(line for line in (ROOT / "Dockerfile").read_text().splitlines()
                       if line.strip().startswith("CMD ["))
    assert "/readyz" in healthcheck and "/healthz" not in healthcheck


def test_resources_come_from_the_memory_budget():
    """limits.memory is memory_budget_bytes for the Deployment's own settings; llvmpipe's
    threads are the CPU limit; the memory request is below the limit."""
    deployment = find("Deployment", "opaline")
    resources = container(deployment)["resources"]
    settings = settings_of(deployment)
    assert mebibytes(resources["limits"]["memory"]) * MIB == memory_budget_bytes(settings)
    assert mebibytes(resources["requests"]["memory"]) < mebibytes(resources["limits"]["memory"])
    assert int(resources["limits"]["cpu"]) == settings.lp_threads * settings.workers


def test_users_are_the_images_numeric_non_root_users():
    uid = re.search(r"useradd .*--uid (\d+)", (ROOT / "Dockerfile").read_text()).group(1)
    nginx_uid = re.search(r"^USER (\d+)$", (ROOT / "deploy/nginx/Dockerfile").read_text(),
                          re.M).group(1)
    for name, expected in (("opaline", uid), ("opaline-cache", nginx_uid)):
        pod = find("Deployment", name)["spec"]["template"]["spec"]
        assert pod["securityContext"]["runAsNonRoot"] is True
        assert pod["securityContext"]["runAsUser"] == int(expected)
        assert pod["containers"][0]["securityContext"]["allowPrivilegeEscalation"] is False


def test_services_budget_and_autoscaler_select_the_deployments():
    for name in ("opaline", "opaline-cache", "opaline-state"):
        labels = find("Deployment", name)["spec"]["template"]["metadata"]["labels"]
        selector = find("Service", name)["spec"]["selector"]
        assert selector.items() <= labels.items()
    state = find("Deployment", "opaline-state")["spec"]["template"]["metadata"]["labels"]
    assert find("PodDisruptionBudget", "opaline-state")["spec"]["selector"]["matchLabels"] == state
    labels = find("Deployment", "opaline")["spec"]["template"]["metadata"]["labels"]
    assert find("PodDisruptionBudget", "opaline")["spec"]["selector"]["matchLabels"] == labels
    target = find("HorizontalPodAutoscaler", "opaline")["spec"]["scaleTargetRef"]
    assert (target["kind"], target["name"]) == ("Deployment", "opaline")
    assert find("HorizontalPodAutoscaler", "opaline")["spec"]["minReplicas"] >= 2


def test_the_replicas_share_the_store_and_it_keeps_what_they_wrote():
    """OPALINE_STATE_URL names the store's Service and port; Redis holds the mesh budget
    without evicting anything itself (Opaline's own LRU does), in an append-only file on
    its volume, and the replicas' /tmp holds their copies of the meshes."""
    deployment = find("Deployment", "opaline")
    settings = settings_of(deployment)
    url = urlsplit(settings.state_url)
    service = find("Service", url.hostname)
    assert url.port == service["spec"]["ports"][0]["port"]
    redis = find("Deployment", url.hostname)
    args = container(redis)["args"]
    option = dict(zip(args[::2], args[1::2], strict=True))
    assert option["--maxmemory-policy"] == "noeviction" and option["--appendonly"] == "yes"
    assert int(option["--maxmemory"].removesuffix("gb")) * 1024 * MIB > settings.mesh_store_bytes
    assert mebibytes(container(redis)["resources"]["limits"]["memory"]) * MIB > 1024 * MIB
    mount = next(m for m in container(redis)["volumeMounts"] if m["mountPath"] == option["--dir"])
    volume = next(v for v in redis["spec"]["template"]["spec"]["volumes"]
                  if v["name"] == mount["name"])
    assert find("PersistentVolumeClaim", volume["persistentVolumeClaim"]["claimName"])
    tmp = next(v for v in deployment["spec"]["template"]["spec"]["volumes"] if v["name"] == "tmp")
    room = mebibytes(tmp["emptyDir"]["sizeLimit"]) * MIB
    assert room >= settings.mesh_store_bytes + settings.mesh_max_bytes


def seconds(directive: str, text: str) -> float:
    return float(re.search(rf"^\s*{directive} (\d+)s;", text, re.M).group(1))


def test_timeouts_cover_the_longest_wait():
    """Nobody gives up before the service does: the pod's grace period (after the preStop
    pause) and nginx's read and cache-lock timeouts are at least the service's wait."""
    deployment = find("Deployment", "opaline")
    wait = Service(settings_of(deployment), None, None, None, None, None).wait_s  # type: ignore[arg-type]
    pause = container(deployment)["lifecycle"]["preStop"]["sleep"]["seconds"]
    assert deployment["spec"]["template"]["spec"]["terminationGracePeriodSeconds"] >= wait + pause
    template = TEMPLATE.read_text()
    for directive in ("proxy_read_timeout", "proxy_cache_lock_timeout", "proxy_cache_lock_age",
                      "proxy_next_upstream_timeout"):
        assert seconds(directive, template) >= wait, directive


def test_the_cache_image_fills_in_a_config_nginx_accepts(tmp_path):
    """deploy/nginx/entrypoint.sh with upstreams and a backup: `nginx -t` accepts the result."""
    need_nginx()
    env = {**os.environ, "OPALINE_NGINX_PREFIX": str(tmp_path), "OPALINE_LISTEN": "127.0.0.1:9",
           "OPALINE_NGINX_TEMPLATE": str(TEMPLATE), "OPALINE_BACKUPS": "127.0.0.1:12",
           "OPALINE_UPSTREAMS": "127.0.0.1:10 127.0.0.1:11",
           "PATH": os.environ.get("PATH", "") + ":/usr/sbin"}
    done = subprocess.run(["sh", str(ROOT / "deploy/nginx/entrypoint.sh"), "-t"], env=env,
                          capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stderr
    config = (tmp_path / "nginx.conf").read_text()
    assert "server 127.0.0.1:11 max_fails=1" in config and "server 127.0.0.1:12 backup;" in config
