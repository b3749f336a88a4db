// The host side of the HAL: configuration, replay and history files (every
// error at file:line:column), simulated faults, and `ascorr thermistors`
// end to end on a replay file and a simulation.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "ascorr_hal/acquisition.hpp"
#include "ascorr_hal_linux/config_file.hpp"
#include "ascorr_hal_linux/replay_source.hpp"
#include "ascorr_hal_linux/simulated_source.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;
namespace fault = hal::fault;

const std::string kExamples = ASCORR_HAL_EXAMPLES;

std::string config_error(const std::string& text) {
    return message_of<text::InputError>([&] { static_cast<void>(hal::parse_config("board.cfg", text)); }, "no error");
}

// The message of ReplaySource's refusal of TEXT, "no error" when it accepts.
std::string replay_error(const std::string& text, const hal::AcquisitionConfig<double>& c) {
    return message_of<text::InputError>([&] { hal::ReplaySource("r.csv", text, c); }, "no error");
}

// The message of parse_history's refusal of TEXT, "no error" when it accepts.
std::string history_error(const std::string& text) {
    return message_of<text::InputError>([&] { static_cast<void>(hal::parse_history("h.csv", text)); }, "no error");
}

// The message of parse_fault's refusal of SPEC, "no error" when it accepts.
std::string fault_error(const std::string& spec, const hal::AcquisitionConfig<double>& c) {
    return message_of<std::invalid_argument>([&] { static_cast<void>(hal::parse_fault(spec, c)); }, "no error");
}

const char* kChannel = "channel name=T1 adc=0 role=t029 a=1.129241e-3 b=2.341077e-4 c=8.775468e-8\n";

TEST(HalConfigFile, ExampleParses) {
    const hal::HalConfig c = hal::read_config(kExamples + "/board.cfg");
    EXPECT_EQ(c.acquisition.channels, 8U);
    EXPECT_EQ(c.acquisition.sampler.samples, 9U);
    EXPECT_EQ(c.acquisition.sampler.settle_us, 2000U);
    EXPECT_EQ(c.acquisition.stale_us, 5000000U);
    EXPECT_EQ(c.gpio.chip, "gpiochip0");
    EXPECT_EQ(c.gpio.miso, 9U);
    EXPECT_EQ(std::string(c.acquisition.channel[1].name), "THT00057");
    EXPECT_EQ(c.acquisition.channel[1].role, hal::Role::kT029);
    EXPECT_EQ(c.acquisition.channel[6].role, hal::Role::kChuA);
    EXPECT_DOUBLE_EQ(c.acquisition.channel[0].sh.c, 8.775468e-8);
    EXPECT_EQ(c.acquisition.channel[0].stuck_frames, 60U);
}

TEST(HalConfigFile, ErrorsNameLineAndColumn) {
    EXPECT_EQ(config_error(std::string("# x\n") + kChannel + "channel name=T1 adc=1 role=t029 a=1 b=2 c=3\n"),
              "board.cfg:3:14: channel 'T1' defined twice");
    EXPECT_EQ(config_error(std::string(kChannel) + "acquisition samples=40\n"),
              "board.cfg:2:21: 'samples': expected an integer in [1, 16], got '40'");
    EXPECT_EQ(config_error("channel name=T1 adc=0 role=t029 a=x b=2 c=3\n"),
              "board.cfg:1:35: 'a': not a finite number: 'x'");
    EXPECT_EQ(config_error("channel name=T1 adc=0 role=t033 a=1 b=2 c=3\n"),
              "board.cfg:1:28: unknown role 't033' (monitor, chu_a, chu_b, chu_c, chu_d, t029, t032)");
    EXPECT_EQ(config_error("channel name=T1 adc=0 role=t029 a=1 b=2\n"), "board.cfg:1:1: channel: missing 'c'");
    EXPECT_EQ(config_error("  chanel name=T1\n"),
              "board.cfg:1:3: unknown directive 'chanel' (acquisition, gpio, channel)");
    EXPECT_EQ(config_error(std::string(kChannel) + "gpio cs=8 clk=8\n"), "board.cfg:2:1: gpio: two signals on line 8");
    EXPECT_EQ(config_error(std::string(kChannel) + "gpio cs 8\n"), "board.cfg:2:6: expected key=value, got 'cs'");
    EXPECT_EQ(config_error(std::string(kChannel) + "channel name=T2 adc=0 role=t029 a=1 b=2 c=3\n"),
              "board.cfg:2:21: ADC input 0 already used by 'T1'");
    EXPECT_EQ(config_error("# nothing\n"), "board.cfg:2:1: no 'channel' line");
    EXPECT_EQ(config_error(std::string(kChannel) + "channel name=T2 adc=1 role=t029 a=1 b=2 c=3 colour=red\n"),
              "board.cfg:2:45: unknown channel key 'colour'");
}

// A curve that is not an NTC's (T must fall as R rises, 1/T > 0) on
// the resistances the channel converts is refused, naming where it fails.
TEST(HalConfigFile, NonMonotonicSteinhartHartIsRefusedWithItsRange) {
    const std::string line = "channel name=T1 adc=0 role=t029 a=1.129241e-3 b=2.341077e-4 ";
    // C < 0: B + 3C·ln²R ≤ 0 from ln R = √(B/(6e-6)) = 6.2465, R = 516.17 ohm, up to r_open.
    const std::string e1 = config_error("# x\n" + line + "c=-2e-6\n");
    EXPECT_NE(e1.find("board.cfg:2:1: channel 'T1': the Steinhart-Hart coefficients are not monotonic (T does not "
                      "fall as R rises) for R in [516.169"),
              std::string::npos)
        << e1;
    EXPECT_NE(e1.find(", 2e+06] ohm"), std::string::npos) << e1;
    EXPECT_NE(e1.find("the channel converts 100 ... 2e+06 ohm"), std::string::npos) << e1;
    // The same curve is fine where it is monotonic: r_open below 516 ohm.
    EXPECT_EQ(config_error(line + "c=-2e-6 r_open=500 r_short=50\n"), "no error");
    // B < 0, C = 0: nowhere monotonic; r_short/r_open and the divider bound the range.
    const std::string e2 = config_error(line.substr(0, line.find("b=")) + "b=-1e-4 c=0 r_short=1000 r_open=1e5\n");
    EXPECT_NE(e2.find("board.cfg:1:1: channel 'T1': the Steinhart-Hart coefficients are not monotonic (T does not fall "
                      "as R rises) for R in [1000, 100000] ohm"),
              std::string::npos)
        << e2;
    // Monotonic, but no temperature: 1/T ≤ 0 at the low end.
    const std::string e3 = config_error("channel name=T1 adc=0 role=t029 a=-1 b=1e-4 c=1e-8\n");
    EXPECT_NE(e3.find("board.cfg:1:1: channel 'T1': the Steinhart-Hart coefficients give no temperature (1/T <= 0) at "
                      "R = 100 ohm"),
              std::string::npos)
        << e3;
    // The example's 10K3A1 channels pass (ExampleParses), and so does any
    // ordinary curve: B > 0, C ≥ 0.
    EXPECT_EQ(config_error(line + "c=0\n"), "no error");
}

// Injected values that are not numbers, and noise that is not
// positive, are refused naming the fault; so are non-finite history values.
TEST(HalSimulated, NaNAndNegativeInjectedValuesAreRefused) {
    const hal::AcquisitionConfig<double> c = hal::read_config(kExamples + "/board.cfg").acquisition;
    EXPECT_EQ(
        fault_error("THT00057:offset:10:20:nan", c),
        "fault 'THT00057:offset:10:20:nan': offset VALUE must be a finite number of degC within +-200, got 'nan'");
    EXPECT_NE(fault_error("THT00057:offset:10:20:inf", c).find("offset VALUE must be a finite number"),
              std::string::npos);
    EXPECT_EQ(fault_error("THT00057:noise:10:20:-5", c),
              "fault 'THT00057:noise:10:20:-5': noise VALUE must be a number of counts in (0, 65535], got '-5'");
    EXPECT_NE(fault_error("THT00057:noise:10:20:0", c).find("noise VALUE must be"), std::string::npos);
    EXPECT_NE(fault_error("THT00057:noise:10:20:nan", c).find("noise VALUE must be"), std::string::npos);
    EXPECT_NE(fault_error("THT00057:noise:10:20:1e300", c).find("noise VALUE must be"), std::string::npos);
    EXPECT_EQ(fault_error("THT00057:open:nan:20", c),
              "fault 'THT00057:open:nan:20': FROM and TO must be finite numbers with FROM < TO");
    EXPECT_NE(fault_error("THT00057:open:0:inf", c).find("FROM and TO must be finite"), std::string::npos);
    EXPECT_EQ(fault_error("THT00057:noise:10:20:4", c), "no error");
    EXPECT_EQ(fault_error("THT00057:offset:10:20:-3.5", c), "no error");
    try {
        hal::parse_history("h.csv", "t,t_chu,t_029,t_032\n1,2,3,4\n2,inf,3,4\n");
        FAIL();
    } catch (const text::InputError& e) {
        EXPECT_STREQ(e.what(), "h.csv:3:3: not a temperature: 'inf' (a finite number, or empty or nan for none)");
    }
    EXPECT_EQ(hal::parse_history("h.csv", "t,t_chu,t_029,t_032\n1,2,3,4\n2,nan,,4\n").size(), 2U);
    // Not above absolute zero: no resistance (was: simulated as a short).
    for (const char* cold : {"-300", "-273.15", "-1e30"}) {
        try {
            hal::parse_history("h.csv", std::string("t,t_chu,t_029,t_032\n1,2,3,4\n2,3,") + cold + ",4\n");
            ADD_FAILURE() << cold;
        } catch (const text::InputError& e) {
            EXPECT_EQ(std::string(e.what()), std::string("h.csv:3:5: not a temperature: '") + cold +
                                                 "' is not above absolute zero (-273.15 degC): no thermistor reads it");
        }
    }
    EXPECT_EQ(hal::parse_history("h.csv", "t,t_chu,t_029,t_032\n1,2,-273.14,4\n").size(), 1U);
}

TEST(HalReplay, ErrorsNameLineAndColumn) {
    const hal::AcquisitionConfig<double> c = hal::read_config(kExamples + "/board.cfg").acquisition;
    EXPECT_EQ(replay_error("t,THT00029,NOPE\n", c), "r.csv:1:12: column 'NOPE' names no configured channel");
    EXPECT_EQ(replay_error("t,THT00029,THT00029.counts\n", c), "r.csv:1:12: channel 'THT00029' recorded twice");
    EXPECT_EQ(replay_error("THT00029\n1\n", c), "r.csv:1:1: no column 't'");
    EXPECT_EQ(replay_error("t,THT00029.counts\n1,4096\n", c), "r.csv:2:3: counts must be an integer in [0, 4095]");
    EXPECT_EQ(replay_error("t,THT00029\n1,warm\n", c), "r.csv:2:3: not a temperature: 'warm'");
    EXPECT_EQ(replay_error("t,THT00029\n-1,3\n", c), "r.csv:2:1: 't' must be a number of seconds in [0, 1e12]");
    EXPECT_EQ(replay_error("t,THT00029\n1,3,4\n", c), "r.csv:2:6: expected 2 fields, found 3");
    EXPECT_EQ(hal::ReplaySource("r.csv", "t,THT00029\n1,3\n2,\n", c).sample_sets(), 2U);
}

TEST(HalSimulated, FaultSpecsAndHistoryErrors) {
    const hal::AcquisitionConfig<double> c = hal::read_config(kExamples + "/board.cfg").acquisition;
    const hal::InjectedFault f = hal::parse_fault("THT00057:offset:10:20:5.5", c);
    EXPECT_EQ(f.channel, 1);
    EXPECT_EQ(f.kind, hal::FaultKind::kOffset);
    EXPECT_EQ(f.value, 5.5);
    EXPECT_THROW(hal::parse_fault("THT00057:melt:10:20", c), std::invalid_argument);
    EXPECT_THROW(hal::parse_fault("NOPE:open:10:20", c), std::invalid_argument);
    EXPECT_THROW(hal::parse_fault("THT00057:open:20:10", c), std::invalid_argument);
    EXPECT_THROW(hal::parse_fault("THT00057:offset:10:20", c), std::invalid_argument);
    EXPECT_THROW(hal::parse_fault("THT00057:open:10:20:1", c), std::invalid_argument);
    try {
        hal::parse_history("h.csv", "t,t_chu,t_029,t_032,chu\n1,2,3,4,E\n");
        FAIL();
    } catch (const text::InputError& e) {
        EXPECT_STREQ(e.what(), "h.csv:2:9: 'chu' must be A, B, C or D");
    }
    EXPECT_THROW(hal::parse_history("h.csv", "t,t_chu,t_029\n"), text::InputError);
}

// A well-formed number beyond double's range says "out of range"
// (as the host's readers do) in every HAL file and in --inject; malformed
// text keeps its own message (the control: 'warm', 'x').
TEST(HalFiles, NumbersBeyondDoubleSayOutOfRange) {
    const std::string huge = "'1e999' is out of range: a number's magnitude is at most 1.797693e+308";
    const std::string tiny =
        "'1e-999' is out of range: a nonzero number's magnitude is at least 4.940656e-324 (write 0)";
    EXPECT_EQ(config_error("channel name=T1 adc=0 role=t029 a=1e999 b=2 c=3\n"), "board.cfg:1:35: 'a': " + huge);
    EXPECT_EQ(config_error("channel name=T1 adc=0 role=t029 a=x b=2 c=3\n"),
              "board.cfg:1:35: 'a': not a finite number: 'x'");
    const hal::AcquisitionConfig<double> c = hal::read_config(kExamples + "/board.cfg").acquisition;
    EXPECT_EQ(replay_error("t,THT00029\n1,1e999\n", c), "r.csv:2:3: " + huge);
    EXPECT_EQ(replay_error("t,THT00029\n1e999,3\n", c), "r.csv:2:1: 't': " + huge);
    EXPECT_EQ(replay_error("t,THT00029\n1,warm\n", c), "r.csv:2:3: not a temperature: 'warm'");
    EXPECT_EQ(history_error("t,t_chu,t_029,t_032\n1,1e-999,3,4\n"), "h.csv:2:3: " + tiny);
    EXPECT_EQ(history_error("t,t_chu,t_029,t_032\n1e999,2,3,4\n"), "h.csv:2:1: 't': " + huge);
    EXPECT_EQ(fault_error("THT00057:offset:10:20:1e999", c), "fault 'THT00057:offset:10:20:1e999': " + huge);
    EXPECT_EQ(fault_error("THT00057:open:1e999:20", c), "fault 'THT00057:open:1e999:20': " + huge);
    EXPECT_EQ(fault_error("THT00057:open:x:20", c),
              "fault 'THT00057:open:x:20': FROM and TO must be finite numbers with FROM < TO");
}

// parse_history was split; what it reads is unchanged (this test
// passes on the earlier, single-function reader too).
TEST(HalSimulated, ParseHistoryReadsEveryRowAsBefore) {
    const std::vector<hal::HistoryRow> a =
        hal::parse_history("h.csv", "x,t_032,chu,t,t_029,t_chu\r\n7,-20,B,1.5,-9,3\r\n,nan,D,2,,\r\n\r\n");
    ASSERT_EQ(a.size(), 2U);
    EXPECT_EQ(a[0].t, 1.5);
    EXPECT_EQ(a[0].head, 1);
    EXPECT_EQ(a[0].t_chu, 3.0);
    EXPECT_EQ(a[0].t_029, -9.0);
    EXPECT_EQ(a[0].t_032, -20.0);
    EXPECT_EQ(a[1].head, 3);
    EXPECT_TRUE(std::isnan(a[1].t_chu) && std::isnan(a[1].t_029) && std::isnan(a[1].t_032));
    const std::vector<hal::HistoryRow> b = hal::parse_history("h.csv", "t,t_chu,t_029,t_032\n0,1,2,3");
    ASSERT_EQ(b.size(), 1U);
    EXPECT_EQ(b[0].head, -1);
    EXPECT_EQ(history_error(""), "h.csv:1:1: empty file (no header)");
    EXPECT_EQ(history_error("t,t_chu,t_029\n"),
              "h.csv:1:1: a temperature history needs columns t, t_chu, t_029, t_032");
    EXPECT_EQ(history_error("t,t_chu,t_029,t_032\n1,2,3\n"), "h.csv:2:6: expected 4 fields, found 3");
    EXPECT_EQ(history_error("t,t_chu,t_029,t_032\n1,2,3,4\n\n2,2,3,4\n"), "h.csv:3:1: expected 4 fields, found 1");
    EXPECT_EQ(history_error("t,t_chu,t_029,t_032\n1,2,x,4\n"),
              "h.csv:2:5: not a temperature: 'x' (a finite number, or empty or nan for none)");
    EXPECT_EQ(history_error("t,t_chu,t_029,t_032\nsoon,2,3,4\n"),
              "h.csv:2:1: 't' must be a number of seconds in [0, 1e12]");
    EXPECT_EQ(history_error("t,chu,t_chu,t_029,t_032\n1,AB,2,3,4\n"), "h.csv:2:3: 'chu' must be A, B, C or D");
}

// Each injected fault class reaches the acquisition as its flag.
TEST(HalSimulated, InjectedFaultsAreDetected) {
    const hal::AcquisitionConfig<double> c = hal::read_config(kExamples + "/board.cfg").acquisition;
    std::vector<hal::HistoryRow> h;
    for (int k = 0; k < 120; ++k) {
        h.push_back({100.0 + k, -1, 3.2 + 0.001 * k, -9.5, -19.8});
    }
    struct Case {
        const char* spec;
        int channel;
        int at;  // sample set (row) index to look at
        hal::FaultBits want;
    };
    const Case cases[] = {
        {"THT00057:open:110:120", 1, 12, fault::kOpen},       {"THT00057:short:110:120", 1, 12, fault::kShort},
        {"THT00057:bus:110:120", 1, 12, fault::kBus},         {"THT00057:offset:110:111:8", 1, 10, fault::kRate},
        {"THT00057:noise:110:120:200", 1, 12, fault::kNoisy}, {"CHU_A:stuck:110:300", 6, 110, fault::kStuck},
        {"CHU_A:drop:110:300", 6, 20, fault::kStale}};
    for (const Case& k : cases) {
        hal::SimulatedSource src(c, hal::history_epochs("history", h), {hal::parse_fault(k.spec, c)});
        hal::TemperatureAcquisition<double> acq(c);
        hal::SampleSet<double> f{};
        for (int i = 0; i <= k.at; ++i) {
            ASSERT_TRUE(src.acquire(f));
            acq.update(f);
        }
        const hal::ChannelReading<double> r = acq.channel(static_cast<std::uint8_t>(k.channel), f.t_us);
        EXPECT_EQ(r.faults & k.want, k.want) << k.spec << " got " << r.faults;
        // Before the fault window the same channel was fine.
        hal::SimulatedSource clean(c, hal::history_epochs("history", h), {});
        hal::TemperatureAcquisition<double> acq2(c);
        for (int i = 0; i <= k.at; ++i) {
            ASSERT_TRUE(clean.acquire(f));
            acq2.update(f);
        }
        EXPECT_EQ(acq2.channel(static_cast<std::uint8_t>(k.channel), f.t_us).faults, 0U) << k.spec;
    }
}

struct CliRun {
    int exit_code;
    std::string out;
    std::string err;
};

CliRun run(const std::string& args, const fs::path& dir) {
    const std::string cmd = std::string(ASCORR_EXE) + " thermistors " + args + " > " + (dir / "out").string() + " 2> " +
                            (dir / "err").string();
    const int rc = std::system(cmd.c_str());
    return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, slurp(dir / "out"), slurp(dir / "err")};
}

TEST(HalCli, ThermistorsOnAReplayFile) {
    const fs::path dir = scratch_dir("hal-cli");
    const CliRun r = run("--config " + kExamples + "/board.cfg --replay " + kExamples + "/replay.csv", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::istringstream in(r.out);
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) {
        lines.push_back(l);
    }
    ASSERT_EQ(lines.size(), 1U + 4U * 11U);
    EXPECT_EQ(lines[0], "t,name,role,counts,ohm,celsius,valid,faults");
    EXPECT_EQ(lines[1], "100.000000,THT00029,t029,,,-9.500,1,");
    EXPECT_EQ(lines[10], "100.000000,t_029,voted,,,-9.500,1,");
    // Sample set 3 (t = 102): THT00057 jumps 6.5 °C (rate, then outvoted), THT00060 open.
    EXPECT_EQ(lines[24], "102.000000,THT00057,t029,,,-3.000,0,rate");
    EXPECT_EQ(lines[27], "102.000000,THT00060,t032,4095,40950000.0,,0,open");
    EXPECT_EQ(lines[32], "102.000000,t_029,voted,,,-9.490,1,");
    // Sample set 4: THT00090 shorted too: T3 withheld; CHU_A kept from t = 102.
    EXPECT_EQ(lines[39], "103.000000,THT00090,t032,0,0.0,,0,short");
    EXPECT_EQ(lines[40], "102.000000,CHU_A,chu_a,,,3.220,1,");
    EXPECT_EQ(lines[44], "103.000000,t_032,voted,,,,0,open|short|no_quorum");
    EXPECT_NE(r.err.find("4 frames, 1 voted values withheld"), std::string::npos) << r.err;
}

TEST(HalCli, ThermistorsSimulatesASolutionsFileWithAFault) {
    const fs::path dir = scratch_dir("hal-cli");
    // A solutions-format file, one solution of head A per second, slowly warming.
    {
        std::ofstream f(dir / "solutions.csv");
        f << "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence\n";
        for (int k = 0; k < 30; ++k) {
            f << 447534187 + k << ",A,1,0,0,0," << 3.2 + 0.01 * k << "," << -9.5 + 0.01 * k << "," << -19.8 + 0.01 * k
              << ",,,,0,1.00\n";
        }
    }
    const CliRun r = run("--config " + kExamples + "/board.cfg --simulate " + (dir / "solutions.csv").string() +
                             " --inject THT00029:open:0:1e12 --inject THT00060:bus:0:1e12",
                         dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find(",THT00029,t029,4095,40950000.0,,0,open\n"), std::string::npos);
    EXPECT_NE(r.out.find(",THT00060,t032,,,,0,bus\n"), std::string::npos);
    EXPECT_EQ(r.out.find(",voted,,,,0,"), std::string::npos) << r.out;  // two of three still agree
    EXPECT_NE(r.out.find("447534216.000000,t_029,voted,,,-9.2"), std::string::npos) << r.out;
    EXPECT_NE(r.err.find("30 frames, 0 voted values withheld"), std::string::npos) << r.err;
}

// A history of three heads at one epoch per second, rows interleaved by head,
// every temperature warming at 0.5 °C/min (10 min, about 5 °C: some 200
// counts), with `step_b` °C added to head B's T_CHU from epoch 300 on.
void write_interleaved_history(const fs::path& path, double step_b, double rate_per_min = 0.5) {
    std::ofstream f(path);
    f << "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence\n";
    const char heads[3] = {'A', 'B', 'C'};
    const double base[3] = {10.0, 12.0, 8.0};
    char buf[160];
    for (int k = 0; k < 600; ++k) {
        const double warm = rate_per_min / 60.0 * k;
        for (int h = 0; h < 3; ++h) {
            const double chu = base[h] + warm + (h == 1 && k >= 300 ? step_b : 0.0);
            std::snprintf(buf, sizeof buf, "%d,%c,1,0,0,0,%.4f,%.4f,%.4f,,,,0,1.00\n", 1000 + k, heads[h], chu,
                          -9.0 + warm, -20.0 + warm);
            f << buf;
        }
    }
}

std::vector<std::string> lines_with(const std::string& text, const std::string& needle) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) {
        if (l.find(needle) != std::string::npos) {
            out.push_back(l);
        }
    }
    return out;
}

// One frame per epoch with every head's truth, at the epoch's time.
// Each row used to be a frame, 16 ms after the previous one, so a one-count
// step of CHU_B between the rows of A and B read as ~1.5 °C/s: a rate fault
// every two or three seconds on a history warming at 0.5 °C/min.
TEST(HalCli, ASlowHistoryWithHeadsInterleavedRaisesNoRateFault) {
    const fs::path dir = scratch_dir("hal-cli");
    write_interleaved_history(dir / "slow.csv", 0.0);
    const CliRun r = run("--config " + kExamples + "/board.cfg --simulate " + (dir / "slow.csv").string(), dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(lines_with(r.out, "rate").size(), 0U) << lines_with(r.out, "rate").front();
    EXPECT_NE(r.err.find("600 frames, 0 voted values withheld"), std::string::npos) << r.err;
    // Frames carry the history's times, every channel at each.
    const std::vector<std::string> b = lines_with(r.out, ",CHU_B,");
    ASSERT_EQ(b.size(), 600U);
    EXPECT_EQ(b[599].substr(0, 19), "1599.000000,CHU_B,c");
    // Not vacuous: the counts did move (0.5 °C/min over 10 min).
    const auto counts = [](const std::string& line) { return std::stoi(line.substr(line.find("chu_b,") + 6)); };
    EXPECT_GT(counts(b[0]) - counts(b[599]), 150);

    // Mutation: a real step of 3 °C on CHU_B in one second is still a rate fault.
    write_interleaved_history(dir / "step.csv", 3.0);
    const CliRun s = run("--config " + kExamples + "/board.cfg --simulate " + (dir / "step.csv").string(), dir);
    ASSERT_EQ(s.exit_code, 0) << s.err;
    const std::vector<std::string> rate = lines_with(s.out, "rate");
    ASSERT_EQ(rate.size(), 1U) << s.out.substr(0, 2000);
    EXPECT_EQ(rate[0].substr(0, 24), "1300.000000,CHU_B,chu_b,") << rate[0];
    EXPECT_NE(rate[0].find(",17.50"), std::string::npos) << rate[0];  // 12 + 300 · 0.5/60 + 3 °C
}

// A steady bench (every temperature constant for 10 min at 1 Hz) raises no
// stuck fault with board.cfg's stuck_frames=60: the simulated converter's
// conversions differ by an LSB as a real one's do (before, noise-free, every
// steady channel was stuck after 60 frames and its vote withheld; a review
// found it).
TEST(HalCli, ASteadyBenchIsNotStuck) {
    const fs::path dir = scratch_dir("hal-cli");
    write_interleaved_history(dir / "steady.csv", 0.0, 0.0);
    const CliRun r = run("--config " + kExamples + "/board.cfg --simulate " + (dir / "steady.csv").string(), dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(lines_with(r.out, "stuck").size(), 0U) << lines_with(r.out, "stuck").front();
    EXPECT_NE(r.err.find("600 frames, 0 voted values withheld"), std::string::npos) << r.err;
    // The readings are the converter's counts of the truth: the median of the
    // dithered conversions (12 °C on CHU_B throughout).
    const std::vector<std::string> b = lines_with(r.out, ",CHU_B,");
    ASSERT_EQ(b.size(), 600U);
    EXPECT_EQ(b.front().substr(b.front().find(",chu_b,")), b.back().substr(b.back().find(",chu_b,")));
    // Not vacuous: an injected stuck fault is still found.
    const CliRun s = run("--config " + kExamples + "/board.cfg --simulate " + (dir / "steady.csv").string() +
                             " --inject CHU_B:stuck:1100:1300",
                         dir);
    ASSERT_EQ(s.exit_code, 0) << s.err;
    EXPECT_FALSE(lines_with(s.out, ",CHU_B,chu_b,").empty());
    EXPECT_FALSE(lines_with(s.out, "stuck").empty()) << s.err;
}

// A replayed value beyond the valid range is printed as it came, however
// large, and flagged (was: cut at 31 characters, 1e40 shown as 1e30).
TEST(HalCli, ALargeReplayedValueIsPrintedWhole) {
    const fs::path dir = scratch_dir("hal-cli");
    std::ofstream(dir / "r.csv") << "t,THT00029,THT00057,THT00087,THT00032,THT00060,THT00090,CHU_A,CHU_B\n"
                                 << "1,1e40,-9,-9,-18,-18,-18,10,10\n";
    const CliRun r = run("--config " + kExamples + "/board.cfg --replay " + (dir / "r.csv").string(), dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::vector<std::string> t = lines_with(r.out, ",THT00029,");
    ASSERT_EQ(t.size(), 1U);
    const std::string tail = ",0,out_of_range";
    ASSERT_EQ(t[0].substr(t[0].size() - tail.size()), tail) << t[0];
    const std::string celsius = t[0].substr(0, t[0].size() - tail.size());
    EXPECT_EQ(std::stod(celsius.substr(celsius.rfind(',') + 1)), 1e40) << t[0];
}

// Rows of one epoch (t to the millisecond) that disagree are refused: one
// thermistor cannot have two temperatures at one time.
TEST(HalCli, RowsOfOneEpochThatDisagreeAreRefused) {
    const fs::path dir = scratch_dir("hal-cli");
    std::ofstream(dir / "h.csv") << "t,chu,t_chu,t_029,t_032\n10,A,5,-9,-20\n10,B,6,-9,-20\n10.0004,C,7,-8.5,-20\n";
    const CliRun r = run("--config " + kExamples + "/board.cfg --simulate " + (dir / "h.csv").string(), dir);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("h.csv:4:13: t_029 = -8.5 at t = 10.000 s disagrees with -9 on line 3 (the same epoch)"),
              std::string::npos)
        << r.err;
    // Rows of other epochs, in any order, are fine.
    std::ofstream(dir / "h2.csv") << "t,chu,t_chu,t_029,t_032\n11,A,5,-9,-20\n10,B,6,-9,-20\n10,A,5,-9,-20\n";
    const CliRun ok = run("--config " + kExamples + "/board.cfg --simulate " + (dir / "h2.csv").string(), dir);
    EXPECT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_NE(ok.err.find("2 frames"), std::string::npos) << ok.err;
}

// A file that cannot be opened was "file:0:0: cannot open: ...".
// No message cites line or column 0; each reader names its file.
TEST(HalCli, AnUnopenableFileIsNamedWithoutLineOrColumnZero) {
    const fs::path dir = scratch_dir("hal-cli");
    const std::string cfg = kExamples + "/board.cfg";
    const std::string missing = (dir / "missing.csv").string();
    fs::create_directory(dir / "adir");
    struct Case {
        std::string args;
        std::string want;
    };
    const Case cases[] = {
        {"--config " + missing + " --replay " + kExamples + "/replay.csv",
         "cannot open " + missing + ": No such file or directory"},
        {"--config " + cfg + " --replay " + missing, "cannot open " + missing + ": No such file or directory"},
        {"--config " + cfg + " --simulate " + missing, "cannot open " + missing + ": No such file or directory"},
        {"--config " + (dir / "adir").string() + " --simulate " + missing,
         "cannot open " + (dir / "adir").string() + ": is a directory, not a file"},
    };
    for (const Case& c : cases) {
        const CliRun r = run(c.args, dir);
        EXPECT_EQ(r.exit_code, 1) << c.args;
        EXPECT_NE(r.err.find(c.want), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find(":0"), std::string::npos) << r.err;
    }
    // The error itself: no line or column when there is none.
    EXPECT_STREQ(text::InputError("f.cfg", 0, 0, "x").what(), "f.cfg: x");
    EXPECT_STREQ(text::InputError("f.cfg", 3, 0, "x").what(), "f.cfg:3: x");
    EXPECT_STREQ(text::InputError("f.cfg", 3, 7, "x").what(), "f.cfg:3:7: x");
}

// Binary data in a configuration, replay or history file is refused
// at file:line:column, and its bytes never reach the terminal (an escaped
// excerpt at most).
TEST(HalCli, BinaryInputIsRefusedAtItsLineAndNeverEchoed) {
    const fs::path dir = scratch_dir("hal-cli");
    const std::string cfg = kExamples + "/board.cfg";
    const std::string good_cfg = slurp(cfg);
    const std::string history = "t,t_chu,t_029,t_032\n1,2,3,4\n";
    const std::string replay = "t,THT00029\n100,-9.5\n";
    struct Bad {
        std::string bytes;   // inserted at the start of line 3
        std::string column;  // of the first bad byte
        std::string what;    // the message after file:3:column:
        std::string excerpt;
    };
    const std::string binary = ": not a text file, line starts \"";
    const std::string latin1 = "; the file may be Latin-1: convert it with iconv -f latin1 -t utf-8), line starts \"";
    const Bad bad[] = {
        {std::string("\0\x01", 2), "1", "binary data (byte 0x00)" + binary, "\\x00\\x01"},
        {"\x1b[2J", "1", "binary data (byte 0x1b)" + binary, "\\x1b[2J"},
        {"x\ry", "2", "a CR not followed by LF (CR-only line ends?)" + binary, "x\\x0dy"},
        // Invalid UTF-8 in a line with a control byte is binary data too.
        {"\xff\xfe\x01", "1", "binary data (byte 0xff)" + binary, "\\xff\\xfe\\x01"},
        // Invalid UTF-8 in an otherwise printable line: not UTF-8 (Latin-1?).
        {"\xff\xfe", "1", "not UTF-8 text (byte 0xff" + latin1, "\\xff\\xfe"},
        {"\xc0\xaf", "1", "not UTF-8 text (byte 0xc0" + latin1, "\\xc0\\xaf"},      // overlong '/'
        {"\xed\xa0\x80", "1", "not UTF-8 text (byte 0xed" + latin1, "\\xed\\xa0"},  // a surrogate
        {"# 25 \xb0"
         "C\n",
         "6", "not UTF-8 text (byte 0xb0" + latin1, "# 25 \\xb0C"},  // Latin-1 '°', a comment
    };
    for (const Bad& b : bad) {
        const auto third_line = [&](const std::string& text) {  // b.bytes at the start of line 3
            const std::size_t at = text.find('\n', text.find('\n') + 1) + 1;
            return text.substr(0, at) + b.bytes + text.substr(at);
        };
        std::ofstream(dir / "b.cfg", std::ios::binary) << third_line(good_cfg);
        std::ofstream(dir / "h.csv", std::ios::binary) << third_line(history + "2,2,3,4\n");
        std::ofstream(dir / "r.csv", std::ios::binary) << third_line(replay + "101,-9.5\n");
        const std::pair<std::string, std::string> runs[] = {
            {"--config " + (dir / "b.cfg").string() + " --simulate " + (dir / "h.csv").string(), "b.cfg"},
            {"--config " + cfg + " --simulate " + (dir / "h.csv").string(), "h.csv"},
            {"--config " + cfg + " --replay " + (dir / "r.csv").string(), "r.csv"},
        };
        for (const auto& [args, file] : runs) {
            const CliRun r = run(args, dir);
            EXPECT_EQ(r.exit_code, 1) << args;
            EXPECT_NE(r.err.find(file + ":3:" + b.column + ": " + b.what), std::string::npos) << r.err;
            EXPECT_NE(r.err.find(b.excerpt), std::string::npos) << r.err;
            EXPECT_EQ(r.err.find(b.bytes), std::string::npos) << "the bytes reached the terminal: " << r.err;
            for (const char c : r.err) {
                const auto u = static_cast<unsigned char>(c);
                EXPECT_TRUE(u == '\n' || (u >= 0x20U && u < 0x7FU)) << "byte " << unsigned{u} << " in " << r.err;
            }
        }
    }
    // Valid UTF-8 (the example's comments have Ω and –) and a byte-order mark pass.
    std::ofstream(dir / "u.csv", std::ios::binary)
        << "\xEF\xBB\xBFt,t_chu,t_029,t_032,note\n1,2,3,4,\xE2\x80\x94 \xF0\x9F\x8C\xA1\n";
    EXPECT_NE(good_cfg.find("\xCE\xA9"), std::string::npos);
    const CliRun u = run("--config " + cfg + " --simulate " + (dir / "u.csv").string(), dir);
    EXPECT_EQ(u.exit_code, 0) << u.err;
}

// docs/contract.md, section 3: RFC 4180 quoting in the header and in columns
// the reader ignores is accepted, as the host readers accept it (ascorr
// correct); in a column it reads a quoted field is refused, naming the column.
// The thermistor readers used to split at every comma ("expected 15 fields,
// found 16") and did not know a quoted header name.
TEST(HalCli, ThermistorReadersAcceptQuotingWhereTheyDoNotReadAndRefuseItWhereTheyDo) {
    const fs::path dir = scratch_dir("hal-cli");
    const std::string cfg = "--config " + kExamples + "/board.cfg ";
    // A solutions file with a quoted header name and a quoted note column
    // holding commas and doubled quotes; the same without: the same output.
    std::ofstream(dir / "q.csv") << "\"t\",chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence,\"note, free\"\n"
                                 << "100,A,1,0,0,0,3.2,-9.5,-19.8,,,,0,1.00,\"a, \"\"b\"\"\"\n"
                                 << "101,A,1,0,0,0,3.3,-9.4,-19.7,,,,0,1.00,\"\"\n"
                                 << "102,A,1,0,0,0,3.4,-9.3,-19.6,,,,0,1.00,plain\n";
    std::ofstream(dir / "p.csv") << "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence,note\n"
                                 << "100,A,1,0,0,0,3.2,-9.5,-19.8,,,,0,1.00,x\n"
                                 << "101,A,1,0,0,0,3.3,-9.4,-19.7,,,,0,1.00,x\n"
                                 << "102,A,1,0,0,0,3.4,-9.3,-19.6,,,,0,1.00,x\n";
    const CliRun q = run(cfg + "--simulate " + (dir / "q.csv").string(), dir);
    const CliRun p = run(cfg + "--simulate " + (dir / "p.csv").string(), dir);
    ASSERT_EQ(q.exit_code, 0) << q.err;
    ASSERT_EQ(p.exit_code, 0) << p.err;
    EXPECT_EQ(q.out, p.out);
    EXPECT_NE(q.err.find("3 frames, 0 voted values withheld"), std::string::npos) << q.err;
    EXPECT_NE(q.out.find("102.000000,t_029,voted,,,-9.290,1,"), std::string::npos) << q.out;  // not vacuous
    // The host reader takes the same file (the contract is one).
    EXPECT_EQ(std::system((std::string(ASCORR_EXE) + " stats --in " + (dir / "q.csv").string() + " > " +
                           (dir / "stats.txt").string() + " 2>&1")
                              .c_str()),
              0)
        << slurp(dir / "stats.txt");

    // A replay file reads every column: a quoted header is accepted.
    std::ofstream(dir / "r.csv") << "\"t\",\"THT00029\"\n100,-9.5\n101,-9.4\n";
    std::ofstream(dir / "rp.csv") << "t,THT00029\n100,-9.5\n101,-9.4\n";
    const CliRun r = run(cfg + "--replay " + (dir / "r.csv").string(), dir);
    const CliRun rp = run(cfg + "--replay " + (dir / "rp.csv").string(), dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, rp.out);
    EXPECT_NE(r.out.find("101.000000,THT00029,t029,,,-9.400,1,"), std::string::npos) << r.out;

    // Quoted fields where the readers read, and malformed quoting: refused at
    // file:line:column, naming the column.
    const std::string quoted = " is a quoted field in a column ascorr reads: write numbers without quotes";
    const std::string history = "t,chu,t_chu,t_029,t_032,note\n";
    struct Case {
        std::string file;
        std::string text;
        std::string option;
        std::string message;
    };
    const Case cases[] = {
        {"t.csv", history + "10,A,\"5\",-9,-20,x\n", "--simulate", "t.csv:2:6: column 't_chu': \"5\"" + quoted},
        {"t2.csv", history + "10,A,5,-9,\"-20\",x\n", "--simulate", "t2.csv:2:11: column 't_032': \"-20\"" + quoted},
        {"time.csv", history + "\"10\",A,5,-9,-20,x\n", "--simulate", "time.csv:2:1: column 't': \"10\"" + quoted},
        {"chu.csv", history + "10,\"A\",5,-9,-20,x\n", "--simulate", "chu.csv:2:4: column 'chu': \"A\"" + quoted},
        {"rq.csv", "t,THT00029\n100,-9.5\n101,\"-9.4\"\n", "--replay",
         "rq.csv:3:5: column 'THT00029': \"-9.4\"" + quoted},
        {"open.csv", history + "10,A,5,-9,-20,\"a note that goes on\nto the next line\"\n", "--simulate",
         "open.csv:2:15: quoted field without its closing quote (a line break inside quotes is not supported"},
        {"after.csv", history + "10,A,5,-9,-20,\"a\"b\n", "--simulate",
         "after.csv:2:18: text after the closing quote of a quoted field"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        std::ofstream(dir / c.file) << c.text;
        const CliRun e = run(cfg + c.option + " " + (dir / c.file).string(), dir);
        EXPECT_EQ(e.exit_code, 1);
        EXPECT_NE(e.err.find(c.message), std::string::npos) << e.err;
    }
}

TEST(HalCli, BadConfigExitsOneWithLocation) {
    const fs::path dir = scratch_dir("hal-cli");
    std::ofstream(dir / "bad.cfg") << "channel name=X adc=9 role=t029 a=1 b=2 c=3\n";
    const CliRun r = run("--config " + (dir / "bad.cfg").string() + " --replay " + kExamples + "/replay.csv", dir);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("bad.cfg:1:20: 'adc': expected an integer in [0, 7], got '9'"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace ascorr::test
