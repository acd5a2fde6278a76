#!/usr/bin/python3
"""A serial line for skylane's link tests: a pseudo-terminal pair. Prints the terminal's device
path, waits until that device is opened by the reader (it shows in /proc/*/fd), writes the
bytes of FILE into the line in chunks of 64 bytes (as a UART would hand them over), then keeps
the line open for HOLD seconds.
  pty_serial.py FILE [HOLD]"""
import os
import pty
import sys
import time

data = open(sys.argv[1], 'rb').read()
hold = float(sys.argv[2]) if len(sys.argv) > 2 else 2.0
master, slave = pty.openpty()
name = os.ttyname(slave)
print(name, flush=True)


def opened_by_another():
    for pid in os.listdir('/proc'):
        if not pid.isdigit() or int(pid) == os.getpid():
            continue
        try:
            for fd in os.listdir('/proc/%s/fd' % pid):
                if os.readlink('/proc/%s/fd/%s' % (pid, fd)) == name:
                    return True
        except OSError:
            pass
    return False


deadline = time.time() + 30
while not opened_by_another() and time.time() < deadline:
    time.sleep(0.05)
time.sleep(0.2)  # the reader sets raw mode
for i in range(0, len(data), 64):
    os.write(master, data[i:i + 64])
    time.sleep(0.002)
time.sleep(hold)
