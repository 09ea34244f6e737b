// CameraSpec: framing and parsing, shared by the CPU and the Ogre renderer.
#include "TreeLod/Camera.h"

#include <gtest/gtest.h>

namespace TreeLod
{
    TEST(Camera, framingKeepsTheWholeBoxInView)
    {
        // Every corner of the box must project inside clip space [-1, 1] with depth in range,
        // for trees of 0.5 m and 500 m alike.
        for (float size : {0.5f, 10.0f, 500.0f})
        {
            glm::vec3 lo(-0.3f * size, 0.0f, -0.2f * size), hi(0.3f * size, size, 0.25f * size);
            for (float az : {0.0f, 90.0f, 217.0f})
            {
                CameraSpec cam = CameraSpec::framing(lo, hi, az, 20.0f, 1.0f);
                glm::mat4 vp = cam.projectionMatrix(1.0f) * cam.viewMatrix();
                for (int c = 0; c < 8; ++c)
                {
                    glm::vec3 p((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
                    glm::vec4 clip = vp * glm::vec4(p, 1.0f);
                    glm::vec3 ndc = glm::vec3(clip) / clip.w;
                    EXPECT_LE(std::abs(ndc.x), 1.0f) << size << " " << az;
                    EXPECT_LE(std::abs(ndc.y), 1.0f) << size << " " << az;
                    EXPECT_LE(std::abs(ndc.z), 1.0f) << size << " " << az;
                }
            }
        }
    }

    TEST(Camera, parseAcceptsOrbitAndExplicitAndRejectsNonsense)
    {
        glm::vec3 lo(-1, 0, -1), hi(1, 4, 1);
        CameraSpec cam;
        std::string error;
        ASSERT_TRUE(CameraSpec::parse("orbit:0,0,2", lo, hi, cam, error)) << error;
        // Azimuth 0 looks from +Z at the centre.
        EXPECT_GT(cam.position.z, 1.0f);
        EXPECT_EQ(cam.target, glm::vec3(0, 2, 0));
        ASSERT_TRUE(CameraSpec::parse("ortho:90,0,1", lo, hi, cam, error)) << error;
        EXPECT_TRUE(cam.orthographic);
        ASSERT_TRUE(CameraSpec::parse("0,2,30,0,2,0,30", lo, hi, cam, error)) << error;
        EXPECT_EQ(cam.fovYDegrees, 30.0f);
        EXPECT_GE(cam.farClip, 30.0f);

        EXPECT_FALSE(CameraSpec::parse("orbit:0,0", lo, hi, cam, error));
        EXPECT_FALSE(CameraSpec::parse("orbit:0,0,-1", lo, hi, cam, error));
        EXPECT_FALSE(CameraSpec::parse("1,2,x,0,0,0", lo, hi, cam, error));
        EXPECT_NE(error.find("'x'"), std::string::npos);
        EXPECT_FALSE(CameraSpec::parse("0,0,0,0,0,0", lo, hi, cam, error));
        EXPECT_FALSE(CameraSpec::parse("nan,0,5,0,0,0", lo, hi, cam, error));
    }

    TEST(Camera, kilometresAwayStillFramesTheTree)
    {
        // A camera 2 km away: near and far clip enclose the tree.
        glm::vec3 lo(-1, 0, -1), hi(1, 4, 1);
        CameraSpec cam;
        std::string error;
        ASSERT_TRUE(CameraSpec::parse("0,2,2000,0,2,0", lo, hi, cam, error));
        EXPECT_LT(cam.nearClip, 1999.0f);
        EXPECT_GT(cam.farClip, 2001.0f);
    }
}
