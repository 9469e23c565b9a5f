"""The assembled ARFLEX runtime (Felix + DRCR) as a child process driven through Gogo on stdin.

Each command is followed by `echo <marker>`; the reply is everything printed before the marker
(prompts removed). The JVM runs in its own session, so the RT halves it spawns share its
process group and `kill()` reaches all of them.
"""
import json
import os
import queue
import re
import shutil
import signal
import subprocess
import threading
import time

BUNDLE_ID = re.compile(r"Bundle ID: (\d+)")


class RuntimeError_(Exception):
    pass


class Runtime:
    def __init__(self, assembly, workdir, rid, log_path, props=None, cpus=None):
        """cpus: CPU list for `taskset -c` (the JVM and, by inheritance, the RT halves' non-RT
        threads run there; the RT threads set their own affinity from the admission)."""
        if not os.path.isfile(os.path.join(assembly, "bin", "felix.jar")):
            raise RuntimeError_(f"runtime assembly not found at {assembly} (build it: mvn -B -q -DskipTests install)")
        self.rid = rid
        self.dir = os.path.join(workdir, "runtime")
        shutil.rmtree(self.dir, ignore_errors=True)
        shutil.copytree(assembly, self.dir)
        args = (["taskset", "-c", str(cpus)] if cpus is not None else []) + [
            "java", f"-Darflex.runtime.id={rid}", "-Dorg.osgi.service.http.port=0"]
        for k, v in (props or {}).items():
            args.append(f"-D{k}={v}")
        args += ["-jar", "bin/felix.jar"]
        self.log = open(log_path, "w")
        self.proc = subprocess.Popen(args, cwd=self.dir, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=self.log, text=True, bufsize=1, start_new_session=True)
        self.out = queue.Queue()
        self.lock = threading.Lock()
        self.marker = 0
        threading.Thread(target=self._pump, daemon=True, name="runtime-out").start()
        try:
            deadline = time.monotonic() + 90
            while True:
                r = self.cmd("arflex:dto", timeout=60)
                if r.startswith("{"):
                    break
                if time.monotonic() > deadline:
                    raise RuntimeError_(f"the DRCR did not start within 90 s (last reply: {r[:200]!r}; log {log_path})")
                time.sleep(0.2)
        except BaseException:  # the caller gets no object to close: stop the JVM here
            self.close(timeout=5)
            raise

    def _pump(self):
        for line in self.proc.stdout:
            self.log.write("out| " + line)
            self.out.put(line.rstrip("\n"))
        self.out.put(None)

    def cmd(self, command, timeout=60.0):
        """Sends one Gogo command; returns its output (stripped)."""
        with self.lock:
            self.marker += 1
            m = f"__latency_end_{self.marker}__"
            try:
                self.proc.stdin.write(f"{command}\necho {m}\n")
                self.proc.stdin.flush()
            except (BrokenPipeError, OSError) as e:
                raise RuntimeError_(f"runtime stdin closed ({e}); see {self.log.name}")
            lines = []
            deadline = time.monotonic() + timeout
            while True:
                left = deadline - time.monotonic()
                try:
                    line = self.out.get(timeout=max(left, 0.001))
                except queue.Empty:
                    raise RuntimeError_(f"no reply to '{command}' within {timeout} s; see {self.log.name}")
                if line is None:
                    raise RuntimeError_(f"the runtime exited during '{command}'; see {self.log.name}")
                while line.startswith("g! "):
                    line = line[3:]
                if line.strip() == m:
                    return "\n".join(lines).strip()
                lines.append(line)

    def dto(self):
        r = self.cmd("arflex:dto")
        try:
            return json.loads(r)
        except ValueError:
            raise RuntimeError_(f"arflex:dto did not answer JSON: {r[:300]!r}")

    def install(self, jar, start=True):
        r = self.cmd("install file:" + os.path.abspath(jar))
        m = BUNDLE_ID.search(r)
        if not m:
            raise RuntimeError_(f"install {jar}: {r}")
        bid = int(m.group(1))
        if start:  # Felix's `install -s` does not start it here: start explicitly
            r = self.cmd(f"start {bid}")
            if r:
                raise RuntimeError_(f"start {bid} ({jar}): {r}")
        return bid

    def uninstall(self, bid):
        r = self.cmd(f"uninstall {bid}")
        if r:
            raise RuntimeError_(f"uninstall {bid}: {r}")

    def felix_update(self, bid):
        r = self.cmd(f"felix:update {bid}")
        if r:
            raise RuntimeError_(f"felix:update {bid}: {r}")

    def instances(self, component):
        return [i for i in self.dto().get("instances", [])
                if component in (i.get("component"), i.get("contract"), i.get("name"))]

    def wait_instance(self, component, state="ACTIVE", timeout=30.0):
        deadline = time.monotonic() + timeout
        last = None
        while time.monotonic() < deadline:
            insts = self.instances(component)
            last = insts
            for i in insts:
                if i.get("state") == state:
                    return i
            time.sleep(0.05)
        raise RuntimeError_(f"{component} not {state} within {timeout} s (instances: {json.dumps(last)[:600]})")

    def wait_gone(self, component, timeout=30.0):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if not self.instances(component):
                return
            time.sleep(0.05)
        raise RuntimeError_(f"{component} still present {timeout} s after uninstall")

    def close(self, timeout=30.0):
        """Stops the framework (end of stdin), then kills the process group past the deadline."""
        if self.proc.poll() is None:
            try:
                self.proc.stdin.close()
            except OSError:
                pass
            try:
                self.proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                pass
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)  # the JVM's own group: RT halves left over
        except (ProcessLookupError, PermissionError):
            pass
        try:
            self.proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            pass
        self.log.close()
