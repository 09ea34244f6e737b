// LodPolicy: a scene's level choice parsed once from its text, and written back.
#include "TreeLod/LodPolicy.h"

#include <gtest/gtest.h>

#include <cmath>

namespace TreeLod
{
    TEST(LodPolicy, parsesTheScriptChoiceAutoWithItsBudgetsAndOneTechnique)
    {
        Result<LodPolicy> script = LodPolicy::parse("");
        ASSERT_TRUE(script.ok());
        EXPECT_EQ(script->mode, LodPolicy::Mode::Script);

        Result<LodPolicy> plain = LodPolicy::parse("auto");
        ASSERT_TRUE(plain.ok());
        EXPECT_TRUE(plain->isAuto());
        EXPECT_TRUE(std::isnan(plain->errorBudget)) << "plain auto takes the script's budget";
        EXPECT_TRUE(std::isnan(plain->frameBudgetMs));

        Result<LodPolicy> error = LodPolicy::parse("auto@0.05");
        ASSERT_TRUE(error.ok());
        EXPECT_FLOAT_EQ(error->errorBudget, 0.05f);
        EXPECT_TRUE(std::isnan(error->frameBudgetMs)) << "no frame budget: the script's";
        Result<LodPolicy> zero = LodPolicy::parse("auto@0");
        ASSERT_TRUE(zero.ok());
        EXPECT_EQ(zero->errorBudget, 0.0f);

        Result<LodPolicy> frame = LodPolicy::parse("auto~40");
        ASSERT_TRUE(frame.ok());
        EXPECT_TRUE(frame->isAuto());
        EXPECT_TRUE(std::isnan(frame->errorBudget)) << "under a frame budget, the script's error budget to start from";
        EXPECT_EQ(frame->frameBudgetMs, 40.0f);

        // Anything else is one technique; whether it exists is the registry's to say.
        for (const char* name : {"lodf", "autox", "entities"})
        {
            Result<LodPolicy> fixed = LodPolicy::parse(name);
            ASSERT_TRUE(fixed.ok()) << name;
            EXPECT_EQ(fixed->mode, LodPolicy::Mode::Fixed) << name;
            EXPECT_EQ(fixed->technique, name);
        }
    }

    TEST(LodPolicy, aBadBudgetIsAnErrorNamingTheElementAndTheRange)
    {
        for (const char* bad : {"auto@", "auto@x", "auto@1.5", "auto@-0.1", "auto@nan", "auto@0.1x"})
        {
            Result<LodPolicy> policy = LodPolicy::parse(bad, "--techniques");
            ASSERT_FALSE(policy.ok()) << bad;
            EXPECT_NE(policy.error().message().find("--techniques"), std::string::npos) << policy.error().message();
            EXPECT_NE(policy.error().message().find("[0, 1]"), std::string::npos) << policy.error().message();
        }
        for (const char* bad : {"auto~", "auto~0", "auto~-5", "auto~inf", "auto~16ms", "auto~1e7"})
        {
            Result<LodPolicy> policy = LodPolicy::parse(bad);
            ASSERT_FALSE(policy.ok()) << bad;
            EXPECT_NE(policy.error().message().find("(0, 1e6]"), std::string::npos) << policy.error().message();
        }
    }

    TEST(LodPolicy, aTransitionFollowsAnyChoice)
    {
        Result<LodPolicy> hard = LodPolicy::parse("auto+fade0");
        ASSERT_TRUE(hard.ok());
        EXPECT_TRUE(hard->isAuto());
        EXPECT_EQ(hard->transition, 0.0f);
        Result<LodPolicy> fixed = LodPolicy::parse("billboard-cloud+fade0.25");
        ASSERT_TRUE(fixed.ok());
        EXPECT_EQ(fixed->technique, "billboard-cloud");
        EXPECT_EQ(fixed->transition, 0.25f);
        EXPECT_TRUE(std::isnan(LodPolicy::parse("auto@0.1")->transition)) << "the script's";
        EXPECT_NE(*LodPolicy::parse("auto+fade0"), *LodPolicy::parse("auto"));
        for (const char* bad : {"auto+fade", "auto+fade-0.1", "auto+fade1.5", "auto+fadenan", "auto+fade0.2x", "auto@2+fade0"})
        {
            Result<LodPolicy> policy = LodPolicy::parse(bad, "--techniques");
            ASSERT_FALSE(policy.ok()) << bad;
            EXPECT_NE(policy.error().message().find("--techniques"), std::string::npos) << policy.error().message();
            EXPECT_NE(policy.error().message().find("[0, 1]"), std::string::npos) << policy.error().message();
        }
    }

    TEST(LodPolicy, aMemoryBudgetFollowsAnyChoiceWithTheTransition)
    {
        Result<LodPolicy> memory = LodPolicy::parse("auto+mem40");
        ASSERT_TRUE(memory.ok());
        EXPECT_TRUE(memory->isAuto());
        EXPECT_EQ(memory->memoryBudgetMB, 40.0f);
        EXPECT_TRUE(std::isnan(memory->transition));
        // Either order with a transition.
        for (const char* text : {"auto@0.02+mem12.5+fade0.2", "auto@0.02+fade0.2+mem12.5"})
        {
            Result<LodPolicy> both = LodPolicy::parse(text);
            ASSERT_TRUE(both.ok()) << text;
            EXPECT_EQ(both->errorBudget, 0.02f);
            EXPECT_EQ(both->memoryBudgetMB, 12.5f);
            EXPECT_EQ(both->transition, 0.2f);
            EXPECT_EQ(both->toString(), "auto@0.02+mem12.5+fade0.2");
        }
        EXPECT_TRUE(std::isnan(LodPolicy::parse("auto")->memoryBudgetMB)) << "the script's";
        EXPECT_NE(*LodPolicy::parse("auto+mem0"), *LodPolicy::parse("auto"));
        for (const char* bad : {"auto+mem", "auto+mem-1", "auto+memnan", "auto+mem4x", "auto+mem2e9"})
        {
            Result<LodPolicy> policy = LodPolicy::parse(bad, "--techniques");
            ASSERT_FALSE(policy.ok()) << bad;
            EXPECT_NE(policy.error().message().find("--techniques: '" + std::string(bad) +
                                                    "': the memory budget after '+mem' must be megabytes"),
                      std::string::npos)
                << policy.error().message();
        }
    }

    TEST(LodPolicy, occlusionOffOrOnFollowsAnyChoice)
    {
        Result<LodPolicy> off = LodPolicy::parse("auto+occ0");
        ASSERT_TRUE(off.ok());
        EXPECT_TRUE(off->isAuto());
        EXPECT_EQ(off->occlusion, 0.0f);
        EXPECT_TRUE(std::isnan(LodPolicy::parse("auto")->occlusion)) << "the script's";
        Result<LodPolicy> all = LodPolicy::parse("impostor+occ1+mem3+fade0.1");
        ASSERT_TRUE(all.ok());
        EXPECT_EQ(all->technique, "impostor");
        EXPECT_EQ(all->occlusion, 1.0f);
        EXPECT_EQ(all->memoryBudgetMB, 3.0f);
        EXPECT_EQ(all->transition, 0.1f);
        EXPECT_EQ(*LodPolicy::parse(all->toString()), *all) << all->toString();
        EXPECT_EQ(off->toString(), "auto+occ0");
        EXPECT_NE(*off, *LodPolicy::parse("auto"));
        for (const char* bad : {"auto+occ", "auto+occ0.5", "auto+occ2", "auto+occyes"})
        {
            Result<LodPolicy> policy = LodPolicy::parse(bad, "--techniques");
            ASSERT_FALSE(policy.ok()) << bad;
            EXPECT_NE(policy.error().message().find("occlusion after '+occ' must be 0 (off) or 1 (on)"), std::string::npos)
                << policy.error().message();
        }
    }

    TEST(LodPolicy, writesBackWhatItParses)
    {
        for (const char* text : {"", "auto", "auto@0.05", "auto@0", "auto@1", "auto~40", "auto~16.5", "lodf",
                                 "auto+fade0", "auto@0.05+fade0.2", "impostor+fade1", "+fade0.1", "auto+mem40",
                                 "auto~16+mem0.5+fade0"})
        {
            Result<LodPolicy> policy = LodPolicy::parse(text);
            ASSERT_TRUE(policy.ok()) << text;
            EXPECT_EQ(policy->toString(), text);
            Result<LodPolicy> again = LodPolicy::parse(policy->toString());
            ASSERT_TRUE(again.ok());
            EXPECT_EQ(*again, *policy) << text;
        }
        // The browser's slider makes a policy without text: it writes as the menu shows it.
        EXPECT_EQ(LodPolicy::automatic(0.04f).toString(), "auto@0.04");
        EXPECT_NE(LodPolicy::automatic(0.04f), LodPolicy::automatic(0.05f));
        EXPECT_NE(LodPolicy::fixed("lodf"), LodPolicy::automatic());
    }
}
