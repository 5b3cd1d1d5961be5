# Sourced by the shared-cache test and benchmark: a real HTTP cache server for
# `shadergen build --cache-url` (docs/variants.md, "The remote cache"): nginx from Debian
# with WebDAV PUT, listening on 127.0.0.1 only, everything it writes (configuration, pid,
# logs, temporaries, the entries) under one directory, run as a child of the caller.
#
#   nginx_dav_start DIR [DIRECTIVES]   sets NGINX_PID, PORT and URL (http://127.0.0.1:PORT/cache);
#                                      DIRECTIVES go into the cache's location (auth_basic ...)
#   nginx_dav_stop        SIGKILL and reap it (nothing to do when it is not running)
NGINX_PID=""
nginx_dav_start() {
  local dir=$1 extra=${2:-} nginx attempt
  nginx=$(command -v nginx || echo /usr/sbin/nginx)
  mkdir -p "$dir/root" "$dir/tmp"
  for attempt in 1 2 3 4 5 6 7 8; do  # a random free port; another on "address in use"
    PORT=$((20000 + (RANDOM * 7 + $$ + attempt * 131) % 40000))
    cat >"$dir/nginx.conf" <<CONF
master_process off;  # one process: killing it stops the server (a test kills it mid-build)
pid $dir/nginx.pid;
events { worker_connections 256; }
http {
  access_log off;
  client_body_temp_path $dir/tmp;
  proxy_temp_path $dir/tmp;
  fastcgi_temp_path $dir/tmp;
  uwsgi_temp_path $dir/tmp;
  scgi_temp_path $dir/tmp;
  server {
    listen 127.0.0.1:$PORT;
    root $dir/root;
    client_max_body_size 64m;
    location /cache/ {
      dav_methods PUT;           # the body goes to a temporary file, renamed into place
      create_full_put_path on;   # ab/abcd...: the two-hex-digit folder on first use
      dav_access user:rw;
      $extra
    }
  }
}
CONF
    "$nginx" -p "$dir" -e "$dir/error.log" -c "$dir/nginx.conf" -g 'daemon off;' 2>>"$dir/start.log" &
    NGINX_PID=$!
    for _ in $(seq 50); do
      if (exec 3<>"/dev/tcp/127.0.0.1/$PORT") 2>/dev/null; then
        URL=http://127.0.0.1:$PORT/cache
        return 0
      fi
      kill -0 "$NGINX_PID" 2>/dev/null || break
      sleep 0.1
    done
    nginx_dav_stop
  done
  echo "cannot start nginx:" >&2
  cat "$dir/start.log" "$dir/error.log" >&2
  return 1
}
nginx_dav_stop() {
  [ -n "$NGINX_PID" ] || return 0
  kill -9 "$NGINX_PID" 2>/dev/null
  wait "$NGINX_PID" 2>/dev/null
  NGINX_PID=""
}
