#!/usr/bin/env python3
"""docker/ without a Docker engine: what can be checked here is checked for real.
- The Dockerfile's build stage installs exactly scripts/debian-packages.txt, in order.
- Every COPY source of the Dockerfile exists in the repository.
- Every synbench command line in the Dockerfile, compose.yaml and synbench.service parses:
  the subcommand exists and every flag is in its --help.
- The install layout the runtime stage copies (`cmake --install` to a prefix) runs: the
  installed synbench, pointed at its profiles and dashboard with the unit's environment,
  serves /api/health, the three default profiles and the dashboard's index.
- The compose topology (serve --bench on emulate over Modbus TCP, bench-compose.json with the
  service name replaced by loopback) starts and the daemon reads the emulator's telemetry.

usage: docker_test.py path/to/synbench path/to/build-dir
"""
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request

BIN, BUILD = sys.argv[1], sys.argv[2]
ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def read(rel):
    with open(os.path.join(ROOT, rel)) as f:
        return f.read()


def packages_of_install_script():
    return [l.strip() for l in read("scripts/debian-packages.txt").splitlines() if l.strip() and not l.strip().startswith("#")]


def packages_of_dockerfile(text):
    m = re.search(r"# synbench-packages-begin.*?\n(.*?)# synbench-packages-end", text, re.S)
    check(m is not None, "Dockerfile marks its package list")
    if not m:
        return []
    body = m.group(1).split("--no-install-recommends", 1)[1].split("&&")[0]
    return [w for w in body.replace("\\", " ").split() if w]


def command_lines():
    """(where, argv after 'synbench') of every synbench invocation in docker/."""
    out = []
    dockerfile = read("docker/Dockerfile")
    cmd = re.search(r'^CMD (\[.*?\])\s*$', dockerfile.replace("\\\n", ""), re.M | re.S)
    check(cmd is not None, "Dockerfile has a JSON CMD")
    if cmd:
        out.append(("Dockerfile CMD", json.loads(cmd.group(1))))
    compose = read("docker/compose.yaml").replace("\n              ", " ")
    for m in re.finditer(r'command: (\[.*?\])', compose):
        out.append(("compose.yaml", json.loads(m.group(1))))
    unit = read("docker/synbench.service")
    m = re.search(r"^ExecStart=/usr/bin/synbench (.*)$", unit, re.M)
    check(m is not None, "synbench.service starts /usr/bin/synbench")
    if m:
        out.append(("synbench.service", shlex.split(m.group(1))))
    return out


def get(url, host):
    req = urllib.request.Request(url, headers={"Host": host})
    with urllib.request.urlopen(req, timeout=10) as r:
        return r.status, r.read()


def start_serve(args, env=None):
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    line = proc.stdout.readline()
    m = re.match(r"listening on http://127\.0\.0\.1:(\d+)", line)
    if not m:
        proc.kill()
        check(False, "serve starts: %r %s" % (line, proc.stderr.read()[-500:]))
        return proc, None
    return proc, int(m.group(1))


def stop(proc):
    proc.terminate()
    try:
        return proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        return -1


def main():
    dockerfile = read("docker/Dockerfile")
    want, have = packages_of_install_script(), packages_of_dockerfile(dockerfile)
    check(have == want, "Dockerfile build stage installs scripts/debian-packages.txt\n  missing: %s\n  extra: %s"
          % (sorted(set(want) - set(have)), sorted(set(have) - set(want))))
    check(dockerfile.count("FROM debian:12") >= 2 and " AS build" in dockerfile and "COPY --from=build" in dockerfile,
          "multi-stage on Debian 12")
    for m in re.finditer(r"^COPY (?!--from)(.*)$", dockerfile, re.M):
        for src in m.group(1).split()[:-1]:
            check(src == "." or os.path.exists(os.path.join(ROOT, src)), "COPY source %s exists" % src)
    for rel in ("docker/bench-compose.json",):
        check(os.path.exists(os.path.join(ROOT, rel)), "%s exists" % rel)

    for where, argv in command_lines():
        sub = argv[0]
        h = subprocess.run([BIN, sub, "--help"], capture_output=True, text=True)
        check(h.returncode == 0, "%s: synbench %s exists" % (where, sub))
        for flag in [a.split("=")[0] for a in argv[1:] if a.startswith("--")]:
            check(flag in h.stdout, "%s: synbench %s knows %s" % (where, sub, flag))

    # The installed layout, as the runtime stage and the unit use it.
    prefix = tempfile.mkdtemp(prefix="synbench-install-")
    r = subprocess.run(["cmake", "--install", BUILD, "--prefix", prefix], capture_output=True, text=True)
    check(r.returncode == 0, "cmake --install (%s)" % r.stderr[-300:])
    installed = os.path.join(prefix, "bin", "synbench")
    share = os.path.join(prefix, "share", "synbench")
    check(os.access(installed, os.X_OK), "bin/synbench installed")
    check(sorted(os.listdir(os.path.join(share, "profiles"))) == ["load_drive.json", "synrm_drive.json", "vfc_meter.json"],
          "the three default profiles installed")
    check(os.path.exists(os.path.join(share, "twin.json")), "twin.json installed")
    web_built = os.path.exists(os.path.join(ROOT, "web", "dist", "index.html"))
    if web_built:
        check(os.path.exists(os.path.join(share, "web", "index.html")), "the dashboard installed")
    unit_env = dict(re.findall(r"^Environment=(\w+)=(.*)$", read("docker/synbench.service"), re.M))
    env = dict(os.environ)
    for k, v in unit_env.items():
        env[k] = v.replace("/usr/share/synbench", share)
    data = tempfile.mkdtemp(prefix="synbench-installed-data-")
    proc, port = start_serve([installed, "serve", "--listen", "127.0.0.1:0", "--data-dir", data], env)
    if port:
        host = "127.0.0.1:%d" % port
        token = open(os.path.join(data, "operator.token")).read().strip()
        s, body = get("http://%s/api/health" % host, host)
        check(s == 200, "installed: /api/health")
        req = urllib.request.Request("http://%s/api/profiles" % host, headers={"Host": host, "Authorization": "Bearer " + token})
        profiles = json.loads(urllib.request.urlopen(req, timeout=10).read())
        check(len(profiles) == 3 and all(p["valid"] for p in profiles), "installed: the profiles load from SYNBENCH_PROFILE_DIR")
        if web_built:
            s, body = get("http://%s/" % host, host)
            check(s == 200 and b"<html" in body.lower() and b"not built" not in body, "installed: the dashboard from SYNBENCH_WEB_DIR")
        check(stop(proc) == 0, "installed: SIGTERM -> exit 0")

    # The compose topology on loopback: emulate on a free port, serve --bench on it.
    emu = subprocess.Popen([BIN, "emulate", "--tcp", "127.0.0.1:0", "--watchdog-timeout-ms", "2000"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = emu.stdout.readline()
    m = re.search(r"127\.0\.0\.1:(\d+)", line)
    check(m is not None, "emulate --tcp 127.0.0.1:0 prints its port (%r)" % line)
    if m:
        bench = json.loads(read("docker/bench-compose.json"))
        check(bench["links"]["emulator"]["host"] == "emulate", "bench-compose.json names the emulate service")
        bench["links"]["emulator"]["host"] = "127.0.0.1"
        bench["links"]["emulator"]["port"] = int(m.group(1))
        cfg = os.path.join(tempfile.mkdtemp(), "bench.json")
        json.dump(bench, open(cfg, "w"))
        data = tempfile.mkdtemp(prefix="synbench-compose-data-")
        proc, port = start_serve([BIN, "serve", "--listen", "127.0.0.1:0", "--data-dir", data, "--bench", cfg])
        if port:
            host = "127.0.0.1:%d" % port
            token = open(os.path.join(data, "operator.token")).read().strip()
            req = urllib.request.Request("http://%s/api/devices" % host, headers={"Host": host, "Authorization": "Bearer " + token})
            devices = json.loads(urllib.request.urlopen(req, timeout=10).read())
            check(any(d["backend"] == "modbus" for d in devices), "serve --bench: devices on Modbus (%s)" % devices)
            udc = 0
            deadline = time.time() + 10
            while time.time() < deadline:
                req = urllib.request.Request("http://%s/api/bench/status" % host, headers={"Host": host, "Authorization": "Bearer " + token})
                st = json.loads(urllib.request.urlopen(req, timeout=10).read())
                udc = (st.get("synrm") or {}).get("udc_V", 0)
                if udc > 300:
                    break
                time.sleep(0.2)
            check(udc > 300, "serve --bench reads the emulator's DC bus over Modbus TCP (%.0f V)" % udc)
            check(stop(proc) == 0, "serve --bench: SIGTERM -> exit 0")
    stop(emu)

    # The unit's hardening, as systemd itself scores it (below 4 is "OK"; 7.5 was "EXPOSED").
    if shutil.which("systemd-analyze"):
        with tempfile.TemporaryDirectory() as d:
            unit = os.path.join(d, "synbench.service")
            shutil.copy(os.path.join(ROOT, "docker", "synbench.service"), unit)
            r = subprocess.run(["systemd-analyze", "security", "--offline=true", unit], capture_output=True, text=True)
            m = re.search(r"Overall exposure level for synbench\.service: ([\d.]+)", r.stdout + r.stderr)
            check(m is not None and float(m.group(1)) < 4.0,
                  "systemd-analyze security scores synbench.service below 4 (%s)" % (m.group(1) if m else r.stderr[-200:]))
    else:
        print("note: systemd-analyze is absent: the unit's hardening score is not checked")

    if failures:
        print("%d failure(s)" % len(failures))
        sys.exit(1)
    print("docker test ok")


if __name__ == "__main__":
    main()
