// WriteQueue, the writer threads of generate's layout and bag: every job runs, one thread keeps
// the order, a failed job's error (naming its file) reaches the caller, notes are kept, the queue
// never holds more than its bound; it needs a thread.
#include "viper/dataset/write_queue.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

namespace {

using viper::dataset::WriteQueue;

TEST(WriteQueue, EveryJobRunsAndOneThreadKeepsTheOrder) {
  std::vector<int> order;
  {
    WriteQueue q(1, 3);
    for (int i = 0; i < 100; ++i)
      q.submit([&order, i] {
        order.push_back(i);
        return std::string();
      });
    EXPECT_TRUE(q.drain().empty());
  }
  ASSERT_EQ(order.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(order[i], i);

  std::atomic<int> done{0};
  WriteQueue four(4, 8);
  for (int i = 0; i < 200; ++i)
    four.submit([&done] {
      ++done;
      return std::string();
    });
  four.drain();
  EXPECT_EQ(done, 200);
  EXPECT_GT(four.workerCpuSeconds(), 0.0);
}

TEST(WriteQueue, AFailedJobIsThrownWithItsMessageAndNotesAreKept) {
  WriteQueue q(2, 4);
  q.submit([] { return std::string("frame 3: 7 flow values became inf"); });
  q.submit([]() -> std::string { throw std::runtime_error("/data/train/img/001/001_00004.png: cannot write PNG: No space left on device"); });
  try {
    q.drain();
    FAIL() << "the failed job was not reported";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("001_00004.png: cannot write PNG"), std::string::npos) << e.what();
  }
  // Later submits fail too: nothing is written after a lost file without the caller knowing.
  EXPECT_THROW(q.submit([] { return std::string(); }), std::runtime_error);
  EXPECT_THROW(q.check(), std::runtime_error);
}

TEST(WriteQueue, NotesComeBackOnce) {
  WriteQueue q(2, 4);
  q.submit([] { return std::string("a note"); });
  q.submit([] { return std::string(); });
  const std::vector<std::string> notes = q.drain();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0], "a note");
  EXPECT_TRUE(q.check().empty());
}

TEST(WriteQueue, SubmitWaitsWhileTheQueueIsFull) {
  std::atomic<bool> release{false};
  std::atomic<int> started{0};
  WriteQueue q(1, 2);
  auto blocked = [&] {
    ++started;
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return std::string();
  };
  q.submit(blocked);  // running
  while (started == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  q.submit(blocked);  // waiting: 1
  q.submit(blocked);  // waiting: 2, the bound
  std::atomic<bool> fourth_in{false};
  std::thread t([&] {
    q.submit([] { return std::string(); });
    fourth_in = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_FALSE(fourth_in) << "submit went past the bound";
  release = true;
  t.join();
  EXPECT_TRUE(fourth_in);
  q.drain();
}

TEST(WriteQueue, NeedsAThreadAndDefaultsToTheCpus) {
  EXPECT_THROW(WriteQueue(0, 1), std::invalid_argument);
  EXPECT_GE(WriteQueue::defaultThreads(), 1u);
  EXPECT_LE(WriteQueue::defaultThreads(), 4u);
}

}  // namespace
