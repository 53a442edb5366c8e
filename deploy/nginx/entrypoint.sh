#!/bin/sh
# The cache image's entry point: fill in opaline.conf.template from the environment,
# then run nginx in the foreground (extra arguments go to nginx, e.g. -t to check).
#   OPALINE_UPSTREAMS  replicas, host:port separated by spaces (required)
#   OPALINE_BACKUPS    servers tried only when those fail (e.g. the replicas' Service again)
#   OPALINE_LISTEN     what nginx listens on (default 8080: no privileges needed)
#   OPALINE_CACHE_MAX  the cache's size on disk (default 1g)
#   OPALINE_NGINX_PREFIX, OPALINE_NGINX_TEMPLATE  where files go, where the template is
set -eu
prefix=${OPALINE_NGINX_PREFIX:-/var/cache/opaline-nginx}
template=${OPALINE_NGINX_TEMPLATE:-/etc/opaline/opaline.conf.template}
mkdir -p "$prefix/tmp"
: > "$prefix/servers"
for upstream in $OPALINE_UPSTREAMS; do
    echo "        server $upstream max_fails=1 fail_timeout=2s;" >> "$prefix/servers"
done
for upstream in ${OPALINE_BACKUPS:-}; do
    echo "        server $upstream backup;" >> "$prefix/servers"
done
sed -e "s|@LISTEN@|${OPALINE_LISTEN:-8080}|" -e "s|@PREFIX@|$prefix|g" \
    -e "s|@CACHE_MAX@|${OPALINE_CACHE_MAX:-1g}|" \
    -e "/@SERVERS@/{r $prefix/servers" -e "d}" "$template" > "$prefix/nginx.conf"
if grep -q "@[A-Z_]*@" "$prefix/nginx.conf"; then
    echo "entrypoint: a placeholder was left unfilled in $prefix/nginx.conf" >&2
    exit 1
fi
# Logs to the container's output, as the Kubernetes logging pipeline expects.
ln -sf /dev/stdout "$prefix/access.log"
ln -sf /dev/stderr "$prefix/error.log"
if [ "$#" -gt 0 ]; then
    exec nginx -p "$prefix" -c "$prefix/nginx.conf" -e stderr "$@"
fi
exec nginx -p "$prefix" -c "$prefix/nginx.conf" -e stderr -g "daemon off;"
