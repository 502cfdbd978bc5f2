#include "src/store/calibration_store.h"

#include <fstream>

#include <gtest/gtest.h>

#include "src/formats/calibration_toml.h"
#include "store_test_support.h"

namespace cdpr::store {
namespace {

using test::calibration_version;
using test::file_bytes;
using test::TempStateDir;

CalibrationStore opened_store(const std::string& dir, int depth) {
  CalibrationStore store({dir, depth});
  const auto opened = store.open();
  EXPECT_TRUE(opened) << (opened ? "" : opened.error().message());
  return store;
}

TEST(CalibrationStore, EmptyStoreHasNoCurrentCalibration) {
  // GIVEN a fresh state directory
  TempStateDir dir;
  CalibrationStore store = opened_store(dir.path(), 3);
  // WHEN the current calibration is loaded
  const auto current = store.load_current();
  // THEN there is none, and that is not an error
  ASSERT_TRUE(current);
  EXPECT_FALSE(current->has_value());
}

TEST(CalibrationStore, CommitMakesTheCalibrationCurrentAndRecordsIt) {
  // GIVEN an empty store
  TempStateDir dir;
  CalibrationStore store = opened_store(dir.path(), 3);
  // WHEN two calibrations are committed
  const auto first = store.commit(calibration_version(1));
  const auto second = store.commit(calibration_version(2));
  // THEN they get increasing sequence numbers and the second is current, byte for byte
  ASSERT_TRUE(first && second);
  EXPECT_EQ(*first, 1);
  EXPECT_EQ(*second, 2);
  const auto current = store.load_current();
  ASSERT_TRUE(current && current->has_value());
  EXPECT_EQ((*current)->seq, 2);
  EXPECT_EQ((*current)->text, formats::format_calibration_toml(calibration_version(2)));
  EXPECT_EQ((*current)->calibration.samples, calibration_version(2).samples);
  const auto history = store.history();
  ASSERT_TRUE(history);
  ASSERT_EQ(history->size(), 2u);
  EXPECT_EQ((*history)[0].seq, 2);
  EXPECT_TRUE((*history)[0].current);
  EXPECT_FALSE((*history)[1].current);
  EXPECT_TRUE((*history)[1].valid);
}

TEST(CalibrationStore, HistoryKeepsTheCurrentPlusDepthVersions) {
  // GIVEN a store keeping 2 previous versions
  TempStateDir dir;
  CalibrationStore store = opened_store(dir.path(), 2);
  // WHEN five versions are committed
  for (int version = 1; version <= 5; ++version) ASSERT_TRUE(store.commit(calibration_version(version)));
  // THEN the newest three remain, newest first
  const auto history = store.history();
  ASSERT_TRUE(history);
  ASSERT_EQ(history->size(), 3u);
  EXPECT_EQ((*history)[0].seq, 5);
  EXPECT_EQ((*history)[1].seq, 4);
  EXPECT_EQ((*history)[2].seq, 3);
}

TEST(CalibrationStore, RollbackRestoresAnOlderVersionByteForByte) {
  // GIVEN three committed versions
  TempStateDir dir;
  CalibrationStore store = opened_store(dir.path(), 5);
  for (int version = 1; version <= 3; ++version) ASSERT_TRUE(store.commit(calibration_version(version)));
  // WHEN rolled back to the first
  const auto rolled = store.rollback(1);
  // THEN the current file equals version 1 and history marks seq 1 as current
  ASSERT_TRUE(rolled) << rolled.error().message();
  EXPECT_EQ(file_bytes(store.current_path()), formats::format_calibration_toml(calibration_version(1)));
  const auto current = store.load_current();
  ASSERT_TRUE(current && current->has_value());
  EXPECT_EQ((*current)->seq, 1);
}

TEST(CalibrationStore, RollbackToAMissingVersionIsRefusedAndChangesNothing) {
  // GIVEN one committed version
  TempStateDir dir;
  CalibrationStore store = opened_store(dir.path(), 5);
  ASSERT_TRUE(store.commit(calibration_version(1)));
  const std::string before = file_bytes(store.current_path());
  // WHEN rolling back to a sequence number that does not exist
  const auto rolled = store.rollback(7);
  // THEN it fails naming the path and errno, and the current file is unchanged
  ASSERT_FALSE(rolled);
  EXPECT_NE(rolled.error().message().find("calibration-000007.toml"), std::string::npos);
  EXPECT_NE(rolled.error().message().find("No such file"), std::string::npos);
  EXPECT_EQ(file_bytes(store.current_path()), before);
}

TEST(CalibrationStore, PruningNeverRemovesARolledBackCurrentVersion) {
  // GIVEN version 1 rolled back to be current, in a store keeping 1 previous version
  TempStateDir dir;
  CalibrationStore store = opened_store(dir.path(), 1);
  ASSERT_TRUE(store.commit(calibration_version(1)));
  ASSERT_TRUE(store.commit(calibration_version(2)));
  ASSERT_TRUE(store.rollback(1));
  // WHEN more versions are committed
  ASSERT_TRUE(store.commit(calibration_version(3)));
  ASSERT_TRUE(store.commit(calibration_version(4)));
  // THEN the history holds the two newest only (seq 1 was not current at the last prune)
  const auto history = store.history();
  ASSERT_TRUE(history);
  ASSERT_EQ(history->size(), 2u);
  EXPECT_EQ((*history)[1].seq, 3);
}

TEST(CalibrationStore, CorruptCurrentFileIsDetectedOnLoad) {
  // GIVEN a committed calibration whose current file was truncated behind the store's back
  TempStateDir dir;
  CalibrationStore store = opened_store(dir.path(), 3);
  ASSERT_TRUE(store.commit(calibration_version(1)));
  const std::string text = file_bytes(store.current_path());
  std::ofstream(store.current_path(), std::ios::trunc) << text.substr(0, text.size() / 2);
  // WHEN it is loaded
  const auto current = store.load_current();
  // THEN the load fails with a parse error naming the file
  ASSERT_FALSE(current);
  EXPECT_EQ(current.error().operation, "parse");
  EXPECT_NE(current.error().message().find("calibration.toml"), std::string::npos);
}

TEST(CalibrationStore, UnparsableTextIsRefusedBeforeAnyFileIsTouched) {
  // GIVEN a committed calibration
  TempStateDir dir;
  CalibrationStore store = opened_store(dir.path(), 3);
  ASSERT_TRUE(store.commit(calibration_version(1)));
  const std::string before = file_bytes(store.current_path());
  // WHEN text that is not a calibration is committed
  const auto committed = store.commit_text("format = 1\nnot a calibration\n");
  // THEN it is refused, the current file is unchanged and no history entry was added
  ASSERT_FALSE(committed);
  EXPECT_EQ(file_bytes(store.current_path()), before);
  const auto history = store.history();
  ASSERT_TRUE(history);
  EXPECT_EQ(history->size(), 1u);
}

TEST(CalibrationStore, OpenRemovesTempFilesOfAnInterruptedWrite) {
  // GIVEN a temp file left by a crash
  TempStateDir dir;
  CalibrationStore store = opened_store(dir.path(), 3);
  const std::string stale = dir.path() + "/" + temp_name(CalibrationStore::kCurrentName);
  std::ofstream(stale) << "half a calib";
  // WHEN the store is opened again
  ASSERT_TRUE(store.open());
  // THEN the temp file is gone
  EXPECT_FALSE(std::filesystem::exists(stale));
}

}  // namespace
}  // namespace cdpr::store
