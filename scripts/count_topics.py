#!/usr/bin/env python3
"""Counts the messages arriving on topics, for the no-drop figure of scripts/measure_pipeline.sh.

Usage: count_topics.py --expect N --timeout S TOPIC[@M] [TOPIC[@M] ...]
Subscribes without deserialising (rospy.AnyMsg), waits until every topic has its count (M where
given, else N) or no message arrived for S seconds, prints one line per topic ("TOPIC: n of N,
first to last message in T s, last one L s after the first topic's last"; L shows a node that
lagged behind its input and caught up from its queue after the input ended) and exits 0 if every
topic got exactly its count, 1 otherwise. Run it with Debian's /usr/bin/python3.
"""
import argparse
import sys
import threading
import time

import rospy


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--expect", type=int, required=True, help="messages each topic must get")
    parser.add_argument("--timeout", type=float, default=20.0, help="seconds of silence that end the count")
    parser.add_argument("topics", nargs="+")
    args = parser.parse_args(rospy.myargv()[1:])

    rospy.init_node("count_topics", anonymous=True)
    expected = {}
    for spec in args.topics:
        topic, _, count = spec.partition("@")
        expected[topic] = int(count) if count else args.expect
    counts = {t: 0 for t in expected}
    first_at, last_at = {}, {}
    lock = threading.Lock()
    last = [time.monotonic()]

    def callback(_msg, topic):
        now = time.monotonic()
        with lock:
            counts[topic] += 1
            first_at.setdefault(topic, now)
            last_at[topic] = now
            last[0] = now

    subs = [rospy.Subscriber(t, rospy.AnyMsg, callback, callback_args=t, queue_size=1000, buff_size=2**28)
            for t in expected]
    print("count_topics: subscribed to %d topics" % len(subs), flush=True)
    while not rospy.is_shutdown():
        with lock:
            done = all(counts[t] >= expected[t] for t in expected)
            silent = time.monotonic() - last[0] > args.timeout
        if done or silent:
            break
        time.sleep(0.1)
    ok = True
    reference = last_at.get(args.topics[0].partition("@")[0])
    for t in expected:
        timing = ""
        if t in last_at:
            timing = ", first to last message in %.2f s" % (last_at[t] - first_at[t])
            if reference is not None:
                timing += ", last one %+.2f s after %s's last" % (last_at[t] - reference, args.topics[0].partition("@")[0])
        print("%s: %d of %d%s" % (t, counts[t], expected[t], timing))
        ok = ok and counts[t] == expected[t]
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
