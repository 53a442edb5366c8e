# Opaline's HTTP service on Mesa's software rasteriser (llvmpipe), headless.
#
#   docker build -t opaline .
#   docker run --rm -p 8000:8000 opaline            # docs at http://localhost:8000/docs
#
# Settings come from OPALINE_* variables (service/opaline/settings.py), e.g.
#   docker run -e OPALINE_QUEUE_SIZE=64 -e OPALINE_GL_BACKEND=osmesa ...

# Stage 1: build the wheel (shaders and presets ship inside it as package data).
FROM python:3.11-slim-bookworm AS build
WORKDIR /src
COPY pyproject.toml README.md ./
COPY service ./service
COPY glsl ./glsl
COPY presets ./presets
RUN pip wheel --no-cache-dir --no-deps -w /wheels .

# Stage 2: the service, without the sources or build tools.
FROM python:3.11-slim-bookworm

# Debian 12's Mesa 22.3: EGL (libegl1 is the glvnd loader, libegl-mesa0 Mesa's vendor
# library), the llvmpipe driver (libgl1-mesa-dri), and OSMesa as the fallback backend
# (removed upstream in Mesa 25.1, still shipped here). glcontext's EGL backend also loads
# libGL.so.1 for the GL entry points, which only libgl1 provides.
RUN apt-get update \
    && apt-get install -y --no-install-recommends \
        libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6 libgl1 \
    && rm -rf /var/lib/apt/lists/*

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    OPALINE_GL_BACKEND=egl \
    OPALINE_PORT=8000

COPY --from=build /wheels /wheels
RUN pip install /wheels/*.whl && rm -rf /wheels

# Non-root; a home gives Mesa somewhere to keep its shader cache.
RUN useradd --create-home --uid 10001 --shell /usr/sbin/nologin opaline
USER opaline
WORKDIR /home/opaline

EXPOSE 8000
# /readyz, not /healthz: the container is healthy only while a worker can render
# (readyz answers 503 when no worker process has a GL context).
HEALTHCHECK --interval=30s --timeout=5s --start-period=30s --retries=3 \
    CMD ["python", "-c", "import os, urllib.request; urllib.request.urlopen('http://127.0.0.1:' + os.environ.get('OPALINE_PORT', '8000') + '/readyz', timeout=4)"]

ENTRYPOINT ["opaline", "serve", "--host", "0.0.0.0"]
