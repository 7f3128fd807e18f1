// Flight-board stub back end: invalid readings by default, records commands.
#include <gtest/gtest.h>

#include "hal/stub/flight_board_stub.hpp"

namespace rocksteady::hal {
namespace {

TEST(FlightBoardStub, ReportsInvalidReadingsOnAFixedPeriod) {
  FlightBoardStub board(0.1);
  SensorSource& source = board;
  RawSensors s;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(source.poll(s));
    EXPECT_EQ(s.seq, k);
    EXPECT_DOUBLE_EQ(s.t, 0.1 * k);
    EXPECT_FALSE(s.gyro.valid);
    EXPECT_FALSE(s.star.valid);
  }
}

TEST(FlightBoardStub, InjectedReadingsAreReturnedOnce) {
  FlightBoardStub board(0.1);
  board.inject(GyroReading{0.0, gnc::Vec3(1, 2, 3), true}, StarTrackerReading{0.0, gnc::Vec4(0, 0, 0, 1), true});
  RawSensors s;
  board.poll(s);
  EXPECT_TRUE(s.gyro.valid);
  EXPECT_EQ(s.gyro.rate, gnc::Vec3(1, 2, 3));
  board.poll(s);
  EXPECT_FALSE(s.gyro.valid);
}

TEST(FlightBoardStub, RecordsTheLastThrusterWrite) {
  FlightBoardStub board;
  ThrusterSink& sink = board;
  ThrusterOutputs out;
  out.enabled = true;
  out.on[5] = true;
  out.force[5] = 42.0;
  sink.write(out, 17, 1.7);
  EXPECT_EQ(board.writes(), 1u);
  EXPECT_EQ(board.last_seq(), 17);
  EXPECT_EQ(board.last_t(), 1.7);
  EXPECT_TRUE(board.last_outputs().on[5]);
  EXPECT_EQ(board.last_outputs().force[5], 42.0);
}

}  // namespace
}  // namespace rocksteady::hal
